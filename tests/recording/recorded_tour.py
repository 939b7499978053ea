"""A whole simulated tour on sim time, in one event loop, recorded to MCAP."""

from __future__ import annotations

import asyncio
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frog_bt.config import Site, load_site
from frog_bt.observers.recording import Recorder
from frog_bt.runtime.executive import Executive, Outcome
from frog_bt.runtime.rehearsal import Rehearsal
from frog_bt.sim import scenario_from
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.traffic import Record
from frog_bt.tree.loader import LoadedTree

# High speed and short content, as in tests/e2e: a tour takes a few seconds of wall time.
FAST: dict[str, Any] = {"speed": 400.0, "content": {"default": 10, "introduction": 8}}


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


async def _record(path: Path, data: dict[str, Any] | None, site: Site | None,
                  tree: LoadedTree | None, wall_timeout: float) -> RecordedTour:
    site = site or load_site()
    recorder = Recorder(path)
    rehearsal = Rehearsal(scenario(data), site=site, tree=tree, prepare=recorder.attach)
    start = rehearsal.sim.clock.now()
    try:
        async with rehearsal:
            outcome = await rehearsal.finish(wall_timeout)
    finally:
        recorder.close()
    return RecordedTour(path, outcome, start, rehearsal.sim.clock.now(), site,
                        rehearsal.executive, rehearsal.sim.received())


def record_tour(path: Path, data: dict[str, Any] | None = None, *, site: Site | None = None,
                tree: LoadedTree | None = None, wall_timeout: float = 60.0) -> RecordedTour:
    """Run one tour of the default scenario (with ``data`` on top) and record it to ``path``."""
    return asyncio.run(_record(path, data, site, tree, wall_timeout))
