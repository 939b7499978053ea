"""The soak, short: `frog-bt run` for 3 tours with a fault of each kind (scripts/soak);
``FROG_BT_SOAK=long`` runs 5 tours with two of each (the longer profile, opt-in)."""

from __future__ import annotations

import asyncio
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from soak_run import Fault, lost_commands, schedule, soak  # noqa: E402

from frog_bt.live.rotation import numbered  # noqa: E402


def test_the_schedule_is_seeded_and_has_every_kind() -> None:
    plan = schedule(100, seed=1)
    assert plan == schedule(100, seed=1) and plan != schedule(100, seed=2)
    kinds = [f.kind for f in plan]
    assert kinds.count("rosbridge") >= 20 and kinds.count("battery") == 1
    assert kinds.count("kill") == 10 and {"frontend", "stale"} <= set(kinds)


LONG = os.environ.get("FROG_BT_SOAK") == "long"
SHORT = [  # a fault of each kind, a kill in the second tour, the battery ending the third
    Fault(1, "rosbridge", 10.0),
    Fault(1, "stale", 20.0),
    Fault(2, "kill", 15.0),
    Fault(2, "frontend", 40.0),
    Fault(3, "battery", 10.0),
]
LONG_PLAN = [
    *SHORT,
    Fault(4, "rosbridge", 30.0),
    Fault(4, "kill", 20.0),
    Fault(5, "frontend", 10.0),
    Fault(5, "stale", 30.0),
]


def test_tours_with_a_fault_of_each_kind_are_all_accounted_for(tmp_path: Path) -> None:
    """Server restarts, front-end restarts, stale perception, kill -9 and a low battery
    (each twice but the battery in the long profile), over 15 % datagram loss: every tour
    that started ended or aborted, no visitor is left without being told, and each
    executive's recordings are readable."""
    tours, plan = (5, LONG_PLAN) if LONG else (3, SHORT)
    report = asyncio.run(soak(tours, 7, tmp_path, speed=300.0, faults=plan, wall_timeout=100.0))
    assert not report.timed_out, report.lines()
    # Each kind happened: faults wait on the simulator's clock for their time in their
    # tour, and one whose tour ended first goes into the next (no wall-clock pacing).
    assert set(report.faults) == {"rosbridge", "stale", "kill", "frontend", "battery"}, (
        report.lines()
    )
    assert report.restarts == report.faults["kill"] >= 1
    assert report.completed + report.aborted >= tours, report.lines()
    assert report.started == report.completed + report.aborted  # all told
    # each kill came mid-tour, and the restarted executive carried that tour to its end
    assert report.resumed == report.faults["kill"], report.lines()
    assert report.unaccounted == 0 and report.stranded == 0, report.lines()
    assert report.abort_reasons and all("battery" in r for r in report.abort_reasons)
    assert len(report.rss_kb) == tours and all(r > 0 for r in report.rss_kb)
    files = numbered(tmp_path / "recordings")
    names = [p.name for _, p in files]
    assert sum("-tour" in n for n in names) >= tours, "\n".join(
        names + report.lines() + report.events
    )
    sent, lost = lost_commands(tmp_path / "recordings")
    assert (sent, lost) == (report.commands_sent, report.commands_lost) and sent > 100
