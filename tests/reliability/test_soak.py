"""The soak, short: `frog-bt run` for 5 tours with two faults of each kind (scripts/soak)."""

from __future__ import annotations

import asyncio
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


def test_five_tours_with_two_faults_of_each_kind_are_all_accounted_for(tmp_path: Path) -> None:
    """Server restarts, front-end restarts, stale perception, kill -9 (twice each) and a
    low battery, over 15 % datagram loss: every tour that started ended or aborted, no
    visitor is left without being told, and each executive's recordings are readable."""
    plan = [
        Fault(1, "rosbridge", 10.0),
        Fault(1, "stale", 20.0),
        Fault(2, "kill", 15.0),
        Fault(2, "frontend", 40.0),
        Fault(3, "battery", 10.0),
        Fault(4, "rosbridge", 30.0),
        Fault(4, "kill", 20.0),
        Fault(5, "frontend", 10.0),
        Fault(5, "stale", 30.0),
    ]
    report = asyncio.run(soak(5, 7, tmp_path, speed=300.0, faults=plan, wall_timeout=150.0))
    assert not report.timed_out, report.lines()
    # Each kind happened: faults wait on the simulator's clock for their time in their
    # tour, and one whose tour ended first goes into the next (no wall-clock pacing).
    assert set(report.faults) == {"rosbridge", "stale", "kill", "frontend", "battery"}, (
        report.lines()
    )
    assert report.restarts == report.faults["kill"] >= 1
    assert report.completed + report.aborted >= 5, report.lines()
    assert report.started == report.completed + report.aborted  # all told
    # each kill came mid-tour, and the restarted executive carried that tour to its end
    assert report.resumed == report.faults["kill"], report.lines()
    assert report.unaccounted == 0 and report.stranded == 0, report.lines()
    assert report.abort_reasons and all("battery" in r for r in report.abort_reasons)
    assert len(report.rss_kb) == 5 and all(r > 0 for r in report.rss_kb)
    files = numbered(tmp_path / "recordings")
    names = [p.name for _, p in files]
    assert sum("-tour" in n for n in names) >= 5, "\n".join(names + report.lines() + report.events)
    sent, lost = lost_commands(tmp_path / "recordings")
    assert (sent, lost) == (report.commands_sent, report.commands_lost) and sent > 100
