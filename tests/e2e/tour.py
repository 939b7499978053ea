"""Whole tours of the real executive against the built-in simulator, on sim time.

Built on :class:`frog_bt.rehearsal.Rehearsal`; adds what tests assert on: the
commands the simulator received, compactly, and what the executive sent to the
front end with its own clock's times. The links run over memory
(:class:`~frog_bt.rosbridge.memory.MemoryWire`, :class:`~frog_bt.frontend.memory.MemoryNet`:
the same protocols, no socket) unless a test asks for sockets (``memory=False``) to test
the wire itself.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from frog_bt.config import Site, load_site
from frog_bt.live.summary import TourSummary
from frog_bt.model.events import FrontendOut, RobotCommand, Ticked
from frog_bt.rehearsal import Rehearsal, free_udp_port
from frog_bt.runtime.executive import Executive, Outcome
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import Simulator, scenario_from
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.traffic import Record
from frog_bt.tree.loader import LoadedTree

# High speed and short content: a whole tour takes a few seconds of wall time.
FAST: dict[str, Any] = {
    "speed": 1000.0,
    "dt": 0.2,  # the world simulated in steps of 0.2 s: half the inputs, the same logic
    "navigation": {"speed": 2.4},
    "content": {"default": 10, "introduction": 8},
}

__all__ = ["FAST", "Running", "Tour", "after_ticks", "describe", "fast", "free_udp_port", "tour"]


def fast(overrides: dict[str, Any] | None = None) -> Scenario:
    """The default scenario, fast, with ``overrides`` on top."""
    return scenario_from("default", {**FAST, **(overrides or {})})


@dataclass
class Tour:
    sim: Simulator
    executive: Executive
    outcome: Outcome
    summary: TourSummary
    site: Site
    sent: list[tuple[float, Any]] = field(default_factory=list)  # (executive time, message)
    published: list[tuple[float, str]] = field(default_factory=list)  # (executive time, topic)

    def commands(self) -> list[str]:
        """What the executive sent, as the simulator received it, compactly."""
        return [describe(r, self.summary) for r in self.sim.received() if r.channel != "ack"]

    def ros_commands(self) -> list[str]:
        return [c for c in self.commands() if c.startswith("/")]

    def frontend_commands(self, *types: str) -> list[str]:
        """Front-end commands, only of ``types`` when given."""
        return [
            c
            for c in self.commands()
            if not c.startswith("/") and (not types or c.split()[0] in types)
        ]


async def after_ticks(exe: Executive, condition: Callable[[], bool], wall: float = 60.0) -> None:
    """Wait, tick by tick (a tap on the executive's ticks, no polling), until
    ``condition()`` holds; ``wall`` seconds only catch a hang."""
    if condition():
        return
    held = asyncio.Event()

    def check(_event: object) -> None:
        if condition():
            held.set()

    listener = listen(exe, check, Ticked)
    try:
        await asyncio.wait_for(held.wait(), wall)
    finally:
        exe.observers.detach(listener)


def describe(record: Record, summary: TourSummary) -> str:
    p: Any = record.payload
    if record.side == "ros":
        if record.channel == "/GotoWayPoint":
            return f"/GotoWayPoint {summary.waypoint_of(p)}"
        return f"{record.channel} {p['data']}"
    fields = " ".join(str(v) for k, v in p.items() if k not in ("type", "seq"))
    return f"{record.channel} {fields}".rstrip()


class Running(Rehearsal):
    """A rehearsal of the default scenario (fast, with ``scenario_data`` on top) that
    keeps a tour summary and the front-end commands sent; ``once`` is off unless asked;
    over memory unless ``memory=False``."""

    def __init__(
        self,
        scenario_data: dict[str, Any],
        *,
        site: Site | None = None,
        tree: LoadedTree | None = None,
        sim: Simulator | None = None,
        listen: tuple[str, int] | None = None,
        once: bool = False,
        memory: bool = True,
        **executive_kwargs: Any,
    ) -> None:
        site = site or load_site()
        self.summary = TourSummary(site)
        self.sent: list[tuple[float, Any]] = []
        self.published: list[tuple[float, str]] = []
        super().__init__(
            None if sim is not None else fast(scenario_data),
            site=site,
            tree=tree,
            sim=sim,
            listen=listen,
            prepare=self._prepare,
            once=once,
            memory=memory,
            **executive_kwargs,
        )

    def _prepare(self, executive: Executive) -> None:
        attach_all(executive, [self.summary])
        listen(executive, lambda e: self.sent.append((e.t, e.message)), FrontendOut)
        listen(executive, lambda e: self.published.append((e.t, e.topic)), RobotCommand)

    def tour(self) -> Tour:
        return Tour(
            self.sim,
            self.executive,
            self.executive.outcome,
            self.summary,
            self.site,
            self.sent,
            self.published,
        )

    async def executive_ticks_until(
        self, condition: Callable[[], bool], wall: float = 60.0
    ) -> None:
        await after_ticks(self.executive, condition, wall)

    def published_at(self, topic: str) -> list[float]:
        """When (by the executive's clock) the executive published on ``topic``."""
        return [t for t, name in self.published if name == topic]


async def run_tour(
    scenario_data: dict[str, Any],
    *,
    site: Site | None = None,
    tree: LoadedTree | None = None,
    wall_timeout: float = 60.0,
) -> Tour:
    async with Running(scenario_data, site=site, tree=tree, once=True) as run:
        await run.finish(wall_timeout)
        return run.tour()


def tour(scenario_data: dict[str, Any], **kwargs: Any) -> Tour:
    return asyncio.run(run_tour(scenario_data, **kwargs))
