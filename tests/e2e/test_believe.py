"""Believe only what is so, end to end on sim time: a stale arrival after a fault, a fault
with a 9 KB message full of terminal escapes, a forced crash and its restart."""

from __future__ import annotations

import asyncio
import json
import logging
import math
import subprocess
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader
from tour import Running, after_ticks

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.live.recording import Recorder
from frog_bt.model import keys
from frog_bt.model.events import Doubted, FrontendOut
from frog_bt.model.frontend import Tour
from frog_bt.model.help import HelpAbout
from frog_bt.offline.replay import Replay
from frog_bt.runtime import checkpoint as checkpoints
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import scenario_from
from frog_bt.text import is_inert

# The sim's scenario files, fast (tests/e2e/tour.py's FAST), as a test's own data
LATE_ARRIVAL = {
    "navigation": {"late": [{"poi": "POI2", "delay": 2.0}]},
    "faults": [
        {"on_arrival": "POI2", "name": "battery monitor", "message": "cell low", "duration": 60}
    ],
}
ESCAPES = "\x1b]0;pwned\x07\x1b[31m\nWARNING frog_bt.alerts: forged line\x1b[0m\n"
LONG_FAULT = {
    "faults": [
        {
            "at": 200,
            "name": "motors\x1b]0;x\x07",
            "message": "Traceback (most recent call last):" + ESCAPES,
            "pad_to": 9216,
            "duration": 60,
        }
    ]
}


def dock_pose_distance(run: Running) -> float:
    world = run.sim.world
    return math.hypot(world.pose.x - world.dock_pose.x, world.pose.y - world.dock_pose.y)


def test_the_shipped_scenarios_are_these():
    late = scenario_from("late_arrival")
    assert late.navigation.late[0].poi == "POI2" and late.faults[0].on_arrival == "POI2"
    long = scenario_from("long_fault")
    assert len(long.faults[0].text) == 9216 and "\x1b" in long.faults[0].text
    assert scenario_from("out_of_order").navigation.late[0].duplicate


def test_a_fault_as_the_robot_reaches_a_stop_ends_docked_at_the_charger(tmp_path: Path):
    record = tmp_path / "late.mcap"

    recorder = Recorder(record)

    async def main() -> None:
        async with Running(LATE_ARRIVAL) as run:
            exe = run.executive
            attach_all(exe, [recorder])  # before its first tick
            doubted: list[Doubted] = []
            listen(exe, doubted.append, Doubted)
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "aborted", 120
            )
            await after_ticks(exe, lambda: run.sim.world.docking_state == "docked", 120)
            assert [d.why for d in doubted] == [
                "arrival at POI2a heard after the drive to SHOP: ignored"
            ]
            docks = run.sim.received("/docking/dock")
            assert [r.payload["data"] for r in docks] == ["undock", "dock"]  # once, at SHOP
            assert dock_pose_distance(run) < 0.1
            assert exe.core.board.get(keys.HELP) is None  # nobody was needed

    try:
        asyncio.run(main())
    finally:
        recorder.close()
    replay = Replay(record, *_site_and_tree())
    result = replay.run()
    assert result.identical, result.divergence
    assert replay.doubts["recorded"] and [w for _, w in replay.doubts["recorded"]] == [
        w for _, w in replay.doubts["replayed"]
    ]


def _site_and_tree():
    site = load_site()
    return site, load_tree(site=site)


def test_a_9kb_fault_with_escapes_aborts_politely_and_nothing_reaches_anyone_raw(
    caplog: pytest.LogCaptureFixture,
):
    caplog.set_level(logging.INFO)

    async def main() -> None:
        async with Running(LONG_FAULT) as run:
            exe = run.executive
            sent: list[Tour] = []
            listen(
                exe,
                lambda e: sent.append(e.message) if isinstance(e.message, Tour) else None,
                FrontendOut,
            )
            aborted = await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "aborted", 120
            )
            reason = aborted.payload["reason"]
            assert reason.startswith("electronics fault: motors\\x1b]0;x\\x07: Traceback")
            assert "… (9,216 bytes)" in reason and is_inert(reason) and len(reason) < 1000
            await after_ticks(exe, lambda: run.sim.world.docking_state == "docked", 120)
            assert dock_pose_distance(run) < 0.1
            assert not exe._stopping.is_set()  # it keeps running
            assert exe.link.stats.sent > 0 and exe.core.faults.total == 0
            status = exe.status_text()
            assert is_inert(status)
            assert [a for a in exe.staff.book.shown() if "\x1b" in a.text] == []

    asyncio.run(main())
    quoted = [r.getMessage() for r in caplog.records if "forged line" in r.getMessage()]
    assert quoted  # the alert and the abort quote the fault, inert: one line each
    for message in quoted:
        assert is_inert(message) and "\\x1b]0;pwned" in message


class Crash(BaseException):
    """A bug that escapes every guard (what a forced crash raises)."""


def test_a_crash_on_a_checkpointed_tour_is_not_resumed_into_again(tmp_path: Path):
    checkpoint = tmp_path / "checkpoint.json"

    async def main() -> None:
        run = Running({}, checkpoint=checkpoint)
        with pytest.raises(Crash):
            async with run:
                run.own_sim = False  # the executive crashes: the robot lives on
                exe = run.executive
                await run.sim.wait_for(
                    lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI1", 60
                )
                await after_ticks(exe, lambda: checkpoint.exists())

                def crash() -> None:
                    raise Crash("a bug that escaped every guard")

                exe.tick = crash  # type: ignore[method-assign]
                exe.wake()
                await asyncio.wait_for(run.task, 30)
        saved = json.loads(checkpoint.read_text())
        assert saved["crashed"] == "Crash: a bug that escaped every guard"
        sim = run.sim
        goals = len(sim.received("/GotoWayPoint"))
        async with Running({}, sim=sim, listen=run.listen, checkpoint=checkpoint) as second:
            exe = second.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None)
            help_ = exe.core.board.get(keys.HELP)
            assert help_ is not None and help_.about is HelpAbout.CRASHED
            assert "a bug that escaped every guard" in help_.detail
            assert exe.core.board.get(keys.RESUME) is None  # the tour is not resumed
            assert not checkpoint.exists()  # set aside: a third start does not try it
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 20)
            assert len(sim.received("/GotoWayPoint")) == goals  # it holds where it is
            await after_ticks(exe, lambda: "executive_crashed" in exe.staff.book.active)
            assert (await exe.staff.submit(Command.RETRY)).ok  # send it home
            await after_ticks(exe, lambda: sim.world.docking_state == "docked", 120)
        await sim.stop()

    asyncio.run(main())


def test_resumes_without_progress_are_counted_and_the_third_start_holds(tmp_path: Path):
    path = tmp_path / "checkpoint.json"
    from frog_bt.model.progress import Progress

    checkpoints.save(path, Progress(("start", "recruit")))
    first = checkpoints.load(path)
    assert first is not None and checkpoints.crash_loop(first) is None
    checkpoints.mark_resumed(path, first)  # killed again before any progress
    second = checkpoints.load(path)
    assert second is not None and checkpoints.crash_loop(second) is None
    checkpoints.mark_resumed(path, second)
    third = checkpoints.load(path)
    assert third is not None
    assert checkpoints.crash_loop(third) == "it stopped 3 times on this tour without going on"
    checkpoints.save(path, Progress(("start", "recruit", "POI1")))  # progress: count reset
    fresh = checkpoints.load(path)
    assert fresh is not None and fresh.resumed == 0 and checkpoints.crash_loop(fresh) is None


@pytest.mark.parametrize("scenario", ["long_fault", "late_arrival"])
def test_the_demo_of_each_scenario_ends_docked_and_prints_nothing_raw(tmp_path, scenario):
    result = subprocess.run(
        [
            *(sys.executable, "-m", "frog_bt", "demo", "--scenario", scenario),
            *("--speed", "300", "--rerun", "off", "--record", str(tmp_path / "t.mcap")),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    out, err = result.stdout, result.stderr
    assert result.returncode == 1  # the tour was aborted: not every stop visited
    assert "outcome:   tour aborted: electronics fault: " in out
    for text in (out, err):
        assert "\x1b" not in text and "\x07" not in text
        assert not any(
            line.startswith("WARNING frog_bt.alerts: forged") for line in text.splitlines()
        )
    if scenario == "late_arrival":
        assert "not believed: 1 robot answer (not acted on)" in out
        assert "arrival at POI2a heard after the drive to SHOP: ignored" in out
    else:
        assert "… (9,216 bytes)" in out
    with open(tmp_path / "t.mcap", "rb") as f:  # docked at the charger, once
        docks = [m.data for _, channel, m in make_reader(f).iter_messages(topics=["/docking/dock"])]
    assert docks == [b'{"data":"undock"}', b'{"data":"dock"}']
