"""One run, one count (issue 39): a tour with an operator skip during POI3's content (the
shape of the seeded season's tour 10, which read "6 of 6" stops and also "Skipped POI3
(operator)"), a restart (the executive stops while POI4's content plays; a second one
resumes the tour from the checkpoint) and a help request (docking fails; a person docks
the robot and answers ``done_by_hand``), recorded by both executives into one directory;
the resumed executive's demo summary, console ``/api/state`` and status count, and the
report's row, table cell and funnel over both recordings, all give the same numbers,
because all of them read the one fold (frog_bt/model/ledger.py), and the resumed
executive's carries on the tour's row its checkpoint kept (frog_bt/runtime/resuming.py)."""

from __future__ import annotations

import asyncio
import json
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest

from frog_bt.cli import main
from frog_bt.clock import SITE_TZ
from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.live.console.day import Day
from frog_bt.live.console.state import LogLines, StopClock, state
from frog_bt.live.rotation import RecordingDir
from frog_bt.live.summary import TourSummary
from frog_bt.model import keys
from frog_bt.model.events import Ticked
from frog_bt.model.outcomes import DockingState
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import scenario_from
from tests.recording.recorded_tour import FAST_TOURS

START = "2026-06-08T10:00:00+02:00"


def _poi(name: str) -> Any:
    return lambda r: r.direction == "in" and r.channel == "start_poi" and r.payload["poi"] == name


async def _until(exe: Any, ok: Any, limit: float) -> None:
    """Wait on the executive's (simulated) clock until ``ok()``."""
    await exe.clock.wait_ready()  # a restarted executive's clock: from its first /clock
    end = exe.clock.now() + limit
    while not ok():
        assert exe.clock.now() < end, "the rehearsal did not get there in time"
        await exe.clock.sleep(1.0)


async def _run(directory: Path, checkpoint: Path) -> dict[str, Any]:
    site = load_site()
    data = {**FAST_TOURS, "start_time": START}
    data["docking"] = {**data.get("docking", {}), "dock_failures": 3}
    before = RecordingDir(directory, 10**12)  # the first executive's --record DIR
    recordings = RecordingDir(directory, 10**12)  # the restarted one's, the same DIR
    summary, day = TourSummary(site), Day("en")
    handed: Any = None  # the simulator, once the first executive has left it running

    def first_prepare(exe: Any) -> None:
        attach_all(exe, [before])

    def prepare(exe: Any) -> None:
        attach_all(exe, [recordings, summary, day])
        listen(exe, lambda _e: exe.outcome.tours >= 1 and exe.stop("tour ended", 0), Ticked)

    try:
        async with Rehearsal(
            scenario_from("default", data),
            site=site,
            prepare=first_prepare,
            once=False,
            checkpoint=checkpoint,
        ) as first:
            sim, where, killed = first.sim, first.listen, first.executive
            await sim.wait_for(_poi("POI3"), 60)
            assert (await killed.staff.submit(Command.SKIP, by="console")).ok
            # the executive stops while POI4's content plays: a restart resumes there
            await sim.wait_for(_poi("POI4"), 60)
            first.own_sim, handed = False, sim
        before.close()
        async with Rehearsal(
            None,
            site=site,
            sim=sim,
            listen=where,
            prepare=prepare,
            once=False,
            checkpoint=checkpoint,
        ) as r:
            exe = r.executive
            await _until(exe, lambda: "docking_failed" in exe.staff.book.active, 1800)
            docking = sim.world.docking  # a person puts the robot on its charger
            docking.state, docking.docked = "docked", True

            def docked() -> bool:
                reading = exe.core.board.get(keys.DOCKING)
                return reading is not None and reading.value == DockingState.DOCKED

            await _until(exe, docked, 30)
            assert (await exe.staff.submit(Command.DONE_BY_HAND, by="console")).ok
            await r.finish(120.0)
            api = state(exe, day, LogLines(owner=exe), StopClock())
    finally:
        before.close()
        recordings.close()
        if handed is not None:
            await handed.stop()
    return {
        "summary": summary,
        "day": day,
        "api": api,
        "ledger": exe.ledger,
        "exe": exe,
        "killed": killed.ledger,
    }


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], dict[str, Any]]:
    directory = tmp_path_factory.mktemp("one") / "frog1"
    live = asyncio.run(_run(directory, directory.parent / "checkpoint.json"))
    target = directory.parent / "report.json"
    assert main(["report", str(directory), "--json", str(target), "--quiet"]) == 0
    return live, json.loads(target.read_text())


def test_the_demo_summary_the_console_and_the_report_agree(run) -> None:
    live, report = run
    (row,) = report["tours"]
    order = list(load_site().tour_plan().content)
    ledger, summary, api = live["ledger"], live["summary"], live["api"]
    (tour,) = ledger.tours
    # the restart: the report joins the two executives' files into one resumed tour; the
    # resumed executive's count carried on the row its checkpoint kept (POI1, POI2 and
    # the skip of POI3 happened before the restart, the help request after it)
    assert row["resumed"] is True and row["restarts"] == 1
    (cut,) = live["killed"].tours
    assert cut.ended == "" and cut.operator_skips == ["POI3"]
    assert tour.started == cut.started is not None
    assert row["start"] == datetime.fromtimestamp(tour.started, SITE_TZ).isoformat(
        timespec="seconds"
    )
    # the fold, live: POI3 left during its content is neither reached nor played
    assert tour.reached == tour.played == ["POI1", "POI2", "POI4", "POI5", "END"]
    assert tour.skips(order) == [("POI3", "operator")]
    assert tour.help == ["docking_failed"]
    assert [(c.command, c.by) for c in tour.commands] == [
        ("skip", "console"),
        ("done_by_hand", "console"),
    ]
    # the report's row and its table's cell
    assert row["stops_reached"] == tour.reached and row["stops_played"] == tour.played
    assert [(s["poi"], s["why"]) for s in row["stops_skipped"]] == tour.skips(order)
    assert [a["kind"] for a in row["alerts"]] == tour.help
    assert row["interventions"] == len(tour.commands)
    assert row["ended"] == tour.ended == "ended"
    assert row["invitations_accepted"] == tour.accepted == ledger.said_yes
    # the funnel: POI3 was not reached
    funnel = report["totals"]["funnel"]
    assert [funnel[p] for p in order] == [int(p in tour.reached) for p in order]
    # the demo summary
    assert summary.stops() == "5 of 6 reached, 5 played; skipped POI3 (operator)"
    assert summary.skipped == ["POI3"] and summary.tours == ["ended"]
    assert "5 of 6 reached" in "\n".join(summary.lines())
    # /api/state: the day's tours, visitors, skipped stops and its line of the tour
    assert api["tours"] == {
        "started": 1,
        "completed": report["totals"]["completed"],
        "aborted": 0,
    }
    assert api["day"]["skipped"] == len(row["stops_skipped"]) == 1
    assert api["day"]["visitors"] == row["invitations_accepted"]
    assert "5 stops; skipped POI3" in api["day"]["last"][0]
    # the executive's outcome, and its status line's count of stops (its own ledger)
    assert live["exe"].outcome.tours == report["totals"]["completed"] == 1
    assert live["exe"].ledger.tours[-1].reached == tour.reached
