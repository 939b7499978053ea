"""Recorded simulated tours on sim time, in one event loop: one whole tour to an MCAP file
(:func:`record_tour`), or tours back to back into a directory as `--record DIR` does
(:func:`record_day`)."""

from __future__ import annotations

import asyncio
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frog_bt.config import Site, load_site
from frog_bt.live.recording import Recorder
from frog_bt.live.rotation import RecordingDir
from frog_bt.model.events import Ticked
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.executive import Executive, Outcome
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import scenario_from
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.traffic import Record
from frog_bt.tree.loader import LoadedTree

# High speed and short content, as in tests/e2e: a tour takes a few seconds of wall time.
FAST: dict[str, Any] = {
    "speed": 1000.0,
    "dt": 0.2,  # the world simulated in steps of 0.2 s: half the inputs, the same logic
    "navigation": {"speed": 2.4},  # 4x the robot's: fewer ticks, the same logic
    "content": {"default": 10, "introduction": 8},
}


def scenario(data: dict[str, Any] | None = None) -> Scenario:
    return scenario_from("default", {**FAST, **(data or {})})


@dataclass
class RecordedTour:
    path: Path
    outcome: Outcome
    start: float  # simulated time span of the tour (the simulator's clock)
    end: float
    site: Site
    executive: Executive
    received: list[Record]  # what the simulator got from the executive


async def _record(
    path: Path,
    data: dict[str, Any] | None,
    site: Site | None,
    tree: LoadedTree | None,
    wall_timeout: float,
) -> RecordedTour:
    site = site or load_site()
    recorder = Recorder(path)
    rehearsal = Rehearsal(
        scenario(data),
        site=site,
        tree=tree,
        prepare=lambda exe: attach_all(exe, [recorder]),
        memory=True,
    )
    start = rehearsal.sim.clock.now()
    try:
        async with rehearsal:
            outcome = await rehearsal.finish(wall_timeout)
    finally:
        recorder.close()
    return RecordedTour(
        path,
        outcome,
        start,
        rehearsal.sim.clock.now(),
        site,
        rehearsal.executive,
        rehearsal.sim.received(),
    )


def record_tour(
    path: Path,
    data: dict[str, Any] | None = None,
    *,
    site: Site | None = None,
    tree: LoadedTree | None = None,
    wall_timeout: float = 60.0,
) -> RecordedTour:
    """Run one tour of the default scenario (with ``data`` on top) and record it to ``path``."""
    return asyncio.run(_record(path, data, site, tree, wall_timeout))


# Tours back to back: a fast robot, short content, a visitor who comes back.
FAST_TOURS: dict[str, Any] = {
    "speed": 1000.0,
    "dt": 0.2,
    "navigation": {"speed": 3.0, "approach_time": 1.0},
    "docking": {"undock_time": 2.0, "dock_time": 3.0},
    "content": {"default": 4, "introduction": 3},
    "frontend": {"idle_at": 1.0, "idle_after_tour": 1.0, "answer_delay": 1.0},
}


def record_day(directory: Path, tours: int, max_bytes: int) -> RecordingDir:
    """Run the executive (not ``once``) until ``tours`` tours have ended, recording to DIR
    as ``frog-bt run --record DIR`` does: an idle and a tour file per tour."""
    recordings = RecordingDir(directory, max_bytes)

    async def run() -> None:
        enough = asyncio.Event()

        def prepare(executive: Any) -> None:
            attach_all(executive, [recordings])
            listen(executive, lambda _e: executive.outcome.tours >= tours and enough.set(), Ticked)

        rehearsal = Rehearsal(
            scenario_from("default", FAST_TOURS),
            site=load_site(),
            prepare=prepare,
            once=False,
            memory=True,
        )
        async with rehearsal:
            await asyncio.wait_for(enough.wait(), 60)
            rehearsal.executive.stop("enough")
            await rehearsal.finish()

    try:
        asyncio.run(run())
    finally:
        recordings.close()
    return recordings
