"""When the robot needs a person (sim time): it holds, asks, and goes on when answered;
what staff decide lasts (out of service before the front end is idle, across a restart);
a pause stops the drive at once."""

from __future__ import annotations

import asyncio
import math
from pathlib import Path

from tour import Running, after_ticks

from frog_bt.engine.operator import Command
from frog_bt.model import keys
from frog_bt.model.events import RobotCommand
from frog_bt.model.help import Help, HelpAbout
from frog_bt.runtime import decisions
from frog_bt.runtime.observer import listen

DOCK_FAILS = {"docking": {"dock_failures": 3}}  # the tour's three tries fail, a fourth works


def docked_by_hand(run: Running) -> None:
    """A person pushes the simulated robot onto its charger."""
    docking = run.sim.world.docking
    docking.state, docking.docked = "docked", True


def test_a_dock_that_fails_holds_and_asks_then_done_by_hand_carries_it_on() -> None:
    async def main() -> None:
        async with Running(DOCK_FAILS) as run:
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 120)
            help_ = exe.core.board.get(keys.HELP)
            assert help_ is not None and help_.about is HelpAbout.DOCK
            assert not exe._stopping.is_set()  # it waits for a person, it does not exit
            await after_ticks(exe, lambda: "docking_failed" in exe.staff.book.active)
            answer = await exe.staff.submit(Command.DONE_BY_HAND)
            assert not answer.ok
            assert "stuck after a failed docking, not on its charger" in answer.text

            docked_by_hand(run)
            await after_ticks(exe, lambda: run.sim.world.docking_state == "docked")
            await run.sim.wait_for(lambda r: r.channel == "/docking/state", 10)
            await after_ticks(
                exe, lambda: (exe.core.board.get(keys.DOCKING) or _no).value == "docked"
            )
            answer = await exe.staff.submit(Command.DONE_BY_HAND)
            assert answer.ok, answer.text
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None)
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "ended", 30
            )
            await after_ticks(exe, lambda: "docking_failed" not in exe.staff.book.active)
            assert not (await exe.staff.submit(Command.RETRY)).ok  # nothing to retry now

    asyncio.run(main())


class _No:
    value = None


_no = _No()


def test_retry_tries_the_failed_step_again() -> None:
    async def main() -> None:
        async with Running(DOCK_FAILS) as run:
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 120)
            docks = len(run.sim.received("/docking/dock"))
            assert (await exe.staff.submit(Command.RETRY)).ok
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "ended", 60
            )
            assert len(run.sim.received("/docking/dock")) > docks  # docked on the retry
            assert run.sim.world.docking_state == "docked"
            assert exe.core.board.get(keys.HELP) is None

    asyncio.run(main())


def test_a_restart_comes_back_still_waiting_for_a_person(tmp_path: Path) -> None:
    checkpoint = tmp_path / "checkpoint.json"

    async def main() -> None:
        async with Running(DOCK_FAILS, checkpoint=checkpoint) as first:
            exe = first.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 120)
            saved = decisions.load(decisions.path_for(checkpoint))
            assert saved.help is not None and saved.help.about is HelpAbout.DOCK
            sim, listen = first.sim, first.listen
            first.own_sim = False  # killed: the simulator (the robot) lives on
        docks = len(sim.received("/docking/dock"))
        async with Running({}, sim=sim, listen=listen, checkpoint=checkpoint) as second:
            exe = second.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None)
            help_ = exe.core.board.get(keys.HELP)
            assert help_ is not None and help_.about is HelpAbout.DOCK
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 20)
            assert len(sim.received("/docking/dock")) == docks  # not re-run unasked
            assert exe.core.board.get(keys.TOUR_STATE) is not None or True
        await sim.stop()

    asyncio.run(main())


def test_service_off_before_frontend_idle_keeps_the_robot_docked() -> None:
    async def main() -> None:
        async with Running({"frontend": {"idle_at": 30.0}}) as run:
            exe = run.executive
            await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
            answer = await exe.staff.submit(Command.SERVICE_OFF)
            assert answer.ok and "no new tour starts" in answer.text
            await run.sim.wait_for(lambda r: r.channel == "frontend_idle", 60)
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 30)
            assert exe.core.board.get(keys.FRONTEND_READY)  # the front end said it is idle
            assert run.sim.received("/docking/dock") == []  # and no undock went out
            assert run.sim.received("tour") == []
            assert (await exe.staff.submit(Command.SERVICE_ON)).ok
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "started", 30
            )

    asyncio.run(main())


def test_a_pause_while_driving_stops_the_robot_within_one_tick() -> None:
    async def main() -> None:
        async with Running({"dt": 0.1}) as run:  # the robot's pose every tick
            exe, world = run.executive, run.sim.world
            await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 60)
            await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 60)  # off to POI0
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 3)  # under way
            stops: list[int] = []  # the tick each stop goal went out in (as it went out)
            listen(
                exe,
                lambda e: (
                    stops.append(exe.core.ticks + 1)
                    if e.goal is not None and e.goal.target == "(stop here)"
                    else None
                ),
                RobotCommand,
            )
            assert (await exe.staff.submit(Command.PAUSE)).ok
            paused_at = exe.core.ticks
            await run.sim.wait_for(
                lambda r: r.channel == "/GotoWayPoint" and r.t >= 0 and _stop_goal(r, world),
                10,
            )
            assert stops and stops[0] <= paused_at + 1  # sent in the tick after the pause
            here = world.pose
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 30)  # seconds go by
            there = world.pose
            assert math.dist((here.x, here.y), (there.x, there.y)) < 0.05  # it stands
            goals = len(run.sim.received("/GotoWayPoint"))
            assert (await exe.staff.submit(Command.RESUME)).ok
            await after_ticks(  # the goal again, and on its way
                exe, lambda: math.dist((there.x, there.y), (world.pose.x, world.pose.y)) > 0.5
            )
            resent = run.sim.received("/GotoWayPoint")[goals:]
            assert resent and resent[0].payload["pose"]["position"]["x"] == 104.0537  # POI0

    asyncio.run(main())


def _stop_goal(record, world) -> bool:
    """A goal at the robot's own pose (not at a POI of the site)."""
    position = record.payload.get("pose", {}).get("position", {})
    x, y = position.get("x"), position.get("y")
    return x is not None and math.dist((x, y), (world.pose.x, world.pose.y)) < 1.0


def test_an_undock_that_fails_asks_and_done_by_hand_starts_the_tour() -> None:
    async def main() -> None:
        async with Running({"docking": {"undock_failures": 1000}}) as run:
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 120)
            assert exe.core.board.get(keys.HELP).about is HelpAbout.UNDOCK  # type: ignore[union-attr]
            docking = run.sim.world.docking  # a person pulls the robot off its charger
            docking.state, docking.docked = "undocked", False
            await after_ticks(
                exe, lambda: (exe.core.board.get(keys.DOCKING) or _no).value == "undocked"
            )
            assert (await exe.staff.submit(Command.DONE_BY_HAND)).ok
            await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 30)  # to POI0

    asyncio.run(main())


def test_a_blocked_way_home_asks_and_retry_drives_home_again() -> None:
    blocked = {
        "navigation": {"failures": [{"poi": "SHOP", "times": 3, "result": "aborted", "after": 2}]}
    }

    async def main() -> None:
        async with Running(blocked) as run:
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 120)
            assert exe.core.board.get(keys.HELP).about is HelpAbout.HOME  # type: ignore[union-attr]
            assert (await exe.staff.submit(Command.RETRY)).ok  # the way is clear now
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "ended", 60
            )
            assert run.sim.world.docking_state == "docked"

    asyncio.run(main())


def test_a_fault_that_persists_with_no_tour_asks_and_holds_until_it_clears() -> None:
    fault = {
        "frontend": {"idle_at": 10_000},
        "faults": [
            {"at": 1, "name": "motors", "level": 2, "message": "overheated", "duration": 20}
        ],
    }

    async def main() -> None:
        async with Running(fault) as run:
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 60)
            assert exe.core.board.get(keys.HELP).about is HelpAbout.FAULT  # type: ignore[union-attr]
            refused = await exe.staff.submit(Command.DONE_BY_HAND)
            assert not refused.ok and "still reports a fault" in refused.text
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None, 60)
            assert run.sim.received("/docking/dock") == []  # no tour started meanwhile

    asyncio.run(main())


def test_out_of_service_and_an_acknowledged_alert_survive_a_restart(
    tmp_path: Path,
) -> None:
    """Staff's decisions are written beside the checkpoint and restored by the next
    executive: still out of service, the acknowledged alert not shown again."""
    checkpoint = tmp_path / "checkpoint.json"
    idle = {"frontend": {"idle_at": 10_000}}

    async def main() -> None:
        async with Running(idle, checkpoint=checkpoint) as first:
            exe = first.executive
            await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
            assert (await exe.staff.submit(Command.SERVICE_OFF)).ok
            first.sim.world.battery.percentage = 20.0
            await after_ticks(exe, lambda: "battery_low" in exe.staff.book.active)
            assert (await exe.staff.submit(Command.ACK_ALERT, "battery_low")).ok
            assert first.keeper is not None
            await after_ticks(exe, first.keeper.kept)  # saved
            sim, listen = first.sim, first.listen
            first.own_sim = False
        saved = decisions.load(decisions.path_for(checkpoint))
        assert not saved.in_service and saved.acknowledged == {"battery_low"}
        async with Running(idle, sim=sim, listen=listen, checkpoint=checkpoint) as second:
            exe = second.executive
            await after_ticks(exe, lambda: "battery_low" in exe.staff.book.active)
            assert exe.core.board.get(keys.IN_SERVICE) is False
            assert "battery_low" not in exe.staff.book.unacknowledged  # not shown again
        await sim.stop()

    asyncio.run(main())


def test_decisions_round_trip_and_a_damaged_file_is_none(tmp_path: Path) -> None:
    path = tmp_path / "c.json.staff"
    kept = decisions.Decisions(
        in_service=False,
        paused=True,
        help=Help(HelpAbout.DOCK, 12.5),
        acknowledged=frozenset({"fault"}),
    )
    decisions.save(path, kept)
    assert decisions.load(path) == kept
    decisions.save(path, decisions.NONE)  # nothing decided: no file
    assert not path.exists() and decisions.load(path) == decisions.NONE
    path.write_text("{not json")
    assert decisions.load(path) == decisions.NONE


def test_a_pause_survives_a_restart_and_the_resumed_tour_waits(tmp_path: Path) -> None:
    checkpoint = tmp_path / "checkpoint.json"

    async def main() -> None:
        async with Running({}, checkpoint=checkpoint) as first:
            exe = first.executive
            await first.sim.wait_for(
                lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI1", 60
            )
            assert (await exe.staff.submit(Command.PAUSE)).ok
            assert first.keeper is not None
            await after_ticks(exe, first.keeper.kept)  # saved
            sim, listen = first.sim, first.listen
            first.own_sim = False
        assert decisions.load(decisions.path_for(checkpoint)).paused
        goals = len(sim.received("/GotoWayPoint"))
        async with Running({}, sim=sim, listen=listen, checkpoint=checkpoint) as second:
            exe = second.executive
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 50)
            assert exe.core.board.get(keys.PAUSED) is True
            assert len(sim.received("/GotoWayPoint")) == goals  # it drives nowhere
            assert (await exe.staff.submit(Command.RESUME)).ok
            await after_ticks(exe, lambda: len(sim.received("/GotoWayPoint")) > goals)
        await sim.stop()

    asyncio.run(main())
