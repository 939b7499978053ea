"""A whole simulated tour on sim time, in one event loop, recorded to MCAP."""

from __future__ import annotations

import asyncio
import socket
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frog_bt.clock import SimClock
from frog_bt.config import Site, load_site
from frog_bt.executive import Executive, Outcome
from frog_bt.recording import Recorder
from frog_bt.sim import Simulator, load_scenario, parse_scenario
from frog_bt.sim.traffic import Record
from frog_bt.tree.loader import LoadedTree, load_tree

# High speed and short content, as in tests/e2e: a tour takes about a second of wall time.
FAST: dict[str, Any] = {"speed": 400.0, "content": {"default": 10, "introduction": 8}}


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """``over`` on top of ``base``: mappings merge, everything else replaces."""
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


def scenario(data: dict[str, Any] | None = None) -> Any:
    base = load_scenario("default").model_dump(mode="json")
    return parse_scenario(merge(base, {**FAST, **(data or {})}))


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
    tree = tree or load_tree(site=site)
    listen = ("127.0.0.1", free_udp_port())
    sim = Simulator(scenario(data), rosbridge_port=0, frontend_port=0, executive=listen)
    start = sim.clock.now()
    await sim.start()
    executive = Executive(site, tree, SimClock(),
                          rosbridge_url=f"ws://127.0.0.1:{sim.rosbridge_port}",
                          frontend=("127.0.0.1", sim.frontend_port), listen=listen,
                          sim_time=True, once=True)
    recorder = Recorder(path)
    recorder.attach(executive)
    try:
        outcome = await asyncio.wait_for(executive.run(), wall_timeout)
    finally:
        await sim.stop()
        recorder.close()
    return RecordedTour(path, outcome, start, sim.clock.now(), site, executive, sim.received())


def record_tour(path: Path, data: dict[str, Any] | None = None, *, site: Site | None = None,
                tree: LoadedTree | None = None, wall_timeout: float = 60.0) -> RecordedTour:
    """Run one tour of the default scenario (with ``data`` on top) and record it to ``path``."""
    return asyncio.run(_record(path, data, site, tree, wall_timeout))
