"""Every live observer attaches the same way (observers.Observer) and closes cleanly."""

from __future__ import annotations

import asyncio
import io
from pathlib import Path

from tour import fast

from frog_bt.behaviours import load_tree
from frog_bt.live.recording import Recorder
from frog_bt.live.rotation import RecordingDir
from frog_bt.live.summary import TourSummary
from frog_bt.live.telemetry import Telemetry
from frog_bt.live.telemetry.process import TelemetryProcess
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.observer import Observer, attach_all, close_all
from frog_bt.runtime.status import StatusLine


def test_every_observer_attaches_to_a_live_executive_and_closes(tmp_path: Path) -> None:
    from frog_bt.config import load_site

    site, tree = load_site(), load_tree()
    out = io.StringIO()
    observers: list[Observer] = [
        Recorder(tmp_path / "one.mcap"),
        RecordingDir(tmp_path / "dir", 10**9),
        TourSummary(site),
        StatusLine(out),
        Telemetry.open(f"save:{tmp_path / 'in.rrd'}", site, tree),
        TelemetryProcess(f"save:{tmp_path / 'child.rrd'}", site, tree),
    ]
    assert all(isinstance(o, Observer) for o in observers)
    attached: list[Observer] = []

    def prepare(executive: Executive) -> None:
        attached.extend(attach_all(executive, observers))

    async def tour() -> None:
        async with Rehearsal(fast(), site=site, tree=tree, prepare=prepare) as run:
            await run.finish()

    asyncio.run(tour())
    close_all(attached)
    close_all(attached)  # idempotent
    assert attached == observers
    summary = observers[2]
    assert isinstance(summary, TourSummary) and summary.complete, summary.lines()
    assert (tmp_path / "one.mcap").stat().st_size > 0
    assert sorted(p.name.split("-")[-1] for p in (tmp_path / "dir").iterdir())[:1] == [
        "idle0001.mcap"
    ]
    assert (tmp_path / "in.rrd").stat().st_size > 0 and (tmp_path / "child.rrd").exists()
    assert "tip TourStatus ended" in out.getvalue()  # the status line's last line: the end
