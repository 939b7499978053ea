"""Run the real executive against the built-in simulator, in one event loop, on sim time."""

from __future__ import annotations

import asyncio
import socket
from dataclasses import dataclass, field
from typing import Any

from frog_bt.clock import SimClock
from frog_bt.config import Site, load_site
from frog_bt.executive import Executive, Outcome
from frog_bt.sim import Simulator, load_scenario, parse_scenario
from frog_bt.sim.traffic import Record
from frog_bt.summary import TourSummary
from frog_bt.tree.loader import LoadedTree, load_tree

FAST = {"speed": 400.0, "content": {"default": 10, "introduction": 8}}


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class Tour:
    sim: Simulator
    executive: Executive
    outcome: Outcome
    summary: TourSummary
    site: Site
    sent: list[tuple[float, Any]] = field(default_factory=list)  # (executive time, message)

    def commands(self) -> list[str]:
        """What the executive sent, as the simulator received it, compactly."""
        return [describe(r, self.summary) for r in self.sim.received()
                if r.channel != "ack"]

    def ros_commands(self) -> list[str]:
        return [c for c in self.commands() if c.startswith("/")]

    def frontend_commands(self, *types: str) -> list[str]:
        """Front-end commands, only of ``types`` when given."""
        return [c for c in self.commands() if not c.startswith("/")
                and (not types or c.split()[0] in types)]


def describe(record: Record, summary: TourSummary) -> str:
    p: Any = record.payload
    if record.side == "ros":
        if record.channel == "/GotoWayPoint":
            return f"/GotoWayPoint {summary.waypoint_of(p)}"
        return f"{record.channel} {p['data']}"
    fields = " ".join(str(v) for k, v in p.items() if k not in ("type", "seq"))
    return f"{record.channel} {fields}".rstrip()



def merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """``over`` on top of ``base``: mappings merge, everything else replaces."""
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


async def run_tour(scenario_data: dict[str, Any], *, site: Site | None = None,
                   tree: LoadedTree | None = None, wall_timeout: float = 60.0,
                   ) -> Tour:
    site = site or load_site()
    tree = tree or load_tree(site=site)
    sc = parse_scenario(merge(load_scenario("default").model_dump(mode="json"),
                              {**FAST, **scenario_data}))
    listen = ("127.0.0.1", free_udp_port())
    sim = Simulator(sc, rosbridge_port=0, frontend_port=0, executive=listen)
    await sim.start()
    executive = Executive(site, tree, SimClock(),
                          rosbridge_url=f"ws://127.0.0.1:{sim.rosbridge_port}",
                          frontend=("127.0.0.1", sim.frontend_port), listen=listen,
                          sim_time=True, once=True)
    summary = TourSummary(site)
    summary.attach(executive.taps)
    sent: list[tuple[float, Any]] = []
    executive.taps.frontend_out.append(lambda t, _type, message: sent.append((t, message)))
    try:
        outcome = await asyncio.wait_for(executive.run(), wall_timeout)
    finally:
        await sim.stop()
    return Tour(sim, executive, outcome, summary, site, sent)


class Running:
    """A simulator and an executive running in this loop, for tests that act mid-tour.

    ``async with Running({...}) as run:`` then e.g. ``await run.sim.wait_for(...)``,
    ``await run.finish()`` for the executive's outcome.
    """

    def __init__(self, scenario_data: dict[str, Any], *, site: Site | None = None,
                 sim: Simulator | None = None, listen: tuple[str, int] | None = None,
                 **executive_kwargs: Any) -> None:
        self.site = site or load_site()
        self.listen = listen  # with sim=: the address that simulator sends events to
        self.scenario_data = scenario_data
        self.sim = sim
        self.own_sim = sim is None
        self.executive_kwargs = executive_kwargs

    async def __aenter__(self) -> Running:
        if self.sim is None:
            sc = parse_scenario(merge(load_scenario("default").model_dump(mode="json"),
                                      {**FAST, **self.scenario_data}))
            self.listen = ("127.0.0.1", free_udp_port())
            self.sim = Simulator(sc, rosbridge_port=0, frontend_port=0, executive=self.listen)
            await self.sim.start()
        assert self.listen is not None
        self.executive = Executive(self.site, load_tree(site=self.site), SimClock(),
                                   rosbridge_url=f"ws://127.0.0.1:{self.sim.rosbridge_port}",
                                   frontend=("127.0.0.1", self.sim.frontend_port),
                                   listen=self.listen, sim_time=True, **self.executive_kwargs)
        self.summary = TourSummary(self.site)
        self.summary.attach(self.executive.taps)
        self.task = asyncio.create_task(self.executive.run())
        return self

    async def finish(self, timeout: float = 60.0) -> Outcome:
        return await asyncio.wait_for(asyncio.shield(self.task), timeout)

    async def __aexit__(self, *exc: object) -> None:
        self.executive.stop("test over")
        await asyncio.wait_for(self.task, 10)
        if self.own_sim:
            await self.sim.stop()

    def tour(self) -> Tour:
        return Tour(self.sim, self.executive, self.executive.outcome, self.summary, self.site)


def tour(scenario_data: dict[str, Any], **kwargs: Any) -> Tour:
    return asyncio.run(run_tour(scenario_data, **kwargs))
