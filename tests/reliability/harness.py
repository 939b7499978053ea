"""A simulated tour run in this event loop, for tests that break things mid-tour.

:class:`TourRun` starts the built-in simulator and the real
:class:`~frog_bt.runtime.executive.Executive` (sim time, ``once``) and records, beside
the simulator's own message log, what the executive published on rosbridge
(with whether its link was up at that moment) and each change of its link.
Tests wait on those records and on the simulator's log, never on sleeps::

    async with TourRun({"speed": 200}) as run:
        await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 10)
        await run.outage(until=...)
        outcome = await run.finish()
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

from frog_bt.config import Site, load_site
from frog_bt.live.summary import TourSummary
from frog_bt.model.events import RobotCommand
from frog_bt.rehearsal import Rehearsal
from frog_bt.rosbridge.link import LinkState
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import Simulator, scenario_from
from frog_bt.sim.traffic import Record

FAST = {
    "speed": 1000.0,
    "dt": 0.2,  # the world simulated in steps of 0.2 s: half the inputs, the same logic
    "navigation": {"speed": 2.4},  # 4x the robot's: fewer ticks, the same logic
    "content": {"default": 10, "introduction": 8},
}
WAIT = 30.0  # wall seconds: a safety net for every wait, never a pace


@dataclass(frozen=True, slots=True)
class Published:
    """One rosbridge publish of the executive, and whether its link was up then."""

    t: float  # executive clock
    topic: str
    msg: dict[str, Any]
    link_up: bool


Event = Published | LinkState


class TourRun(Rehearsal):
    def __init__(
        self,
        scenario: dict[str, Any] | None = None,
        *,
        site: Site | None = None,
        secret: str | None = None,
        sim_secret: str | None = None,
    ) -> None:
        site = site or load_site()
        self.events: list[Event] = []
        self._waiters: list[tuple[Callable[[Event], bool], asyncio.Future[Event]]] = []
        self.summary = TourSummary(site)
        super().__init__(
            scenario_from("default", {**FAST, **(scenario or {})}),
            site=site,
            sim_secret=sim_secret,
            secret=secret,
            prepare=self._prepare,
        )

    def _prepare(self, exe: Executive) -> None:
        attach_all(exe, [self.summary])
        listen(
            exe,
            lambda out: self._add(Published(out.t, out.topic, out.msg, exe.client.link.connected)),
            RobotCommand,
        )
        exe.link_listeners.append(self._add)  # after the executive's own (it re-sends the goal)

    # ------------------------------------------------------------ records and waits

    def _add(self, event: Event) -> None:
        self.events.append(event)
        keep = []
        for predicate, fut in self._waiters:
            if fut.done():
                continue
            if predicate(event):
                fut.set_result(event)
            else:
                keep.append((predicate, fut))
        self._waiters = keep

    async def wait_event(
        self, predicate: Callable[[Event], bool], *, since: int = 0, timeout: float = WAIT
    ) -> Event:
        """The first event from index ``since`` on (logged or to come) satisfying ``predicate``."""
        for event in self.events[since:]:
            if predicate(event):
                return event
        fut: asyncio.Future[Event] = asyncio.get_running_loop().create_future()
        self._waiters.append((predicate, fut))
        return await asyncio.wait_for(fut, timeout)

    async def link(self, up: bool) -> LinkState:
        """Wait until the executive's rosbridge link is up (or down)."""
        if self.executive.client.link.connected == up:
            return self.executive.client.link
        event = await self.wait_event(
            lambda e: isinstance(e, LinkState) and e.connected == up, since=len(self.events)
        )
        assert isinstance(event, LinkState)
        return event

    @property
    def published(self) -> list[Published]:
        return [e for e in self.events if isinstance(e, Published)]

    async def outage(self, until: Awaitable[Any]) -> Outage:
        """Stop the simulator's rosbridge, await ``until``, start it again; wait for the link.

        Checks on the way that the executive's clock stood still while the link was down
        (under sim time ``/clock`` comes over that link).
        """
        await self.sim.stop_rosbridge()
        await self.link(False)
        frozen = self.executive.clock.now()
        sim_down = self.sim.world.now
        result = await until
        assert self.executive.clock.now() == frozen, "the executive's clock moved while down"
        self.sim.pause()  # the reconnect takes wall time, which must not change the tour
        sim_up = self.sim.world.now
        await self.sim.start_rosbridge()
        await self.link(True)
        self.sim.pause(False)
        return Outage(sim_down, sim_up, frozen, result)

    # ------------------------------------------------------------ what the simulator saw

    def describe(self, record: Record) -> str:
        p: Any = record.payload
        if record.side == "ros":
            if record.channel == self.site.topic("goto"):
                return f"{record.channel} {self.summary.waypoint_of(p)}"
            return f"{record.channel} {p.get('data')}"
        fields = " ".join(str(v) for k, v in p.items() if k not in ("type", "seq"))
        return f"{record.channel} {fields}".rstrip()

    def commands(self, *types: str) -> list[str]:
        """What the simulator received from the executive (acks left out), compactly;
        only front-end commands of ``types`` when given."""
        out = [self.describe(r) for r in self.sim.received() if r.channel != "ack"]
        if types:
            out = [c for c in out if not c.startswith("/") and c.split()[0] in types]
        return out

    def ros_commands(self) -> list[str]:
        return [c for c in self.commands() if c.startswith("/")]


@dataclass(frozen=True, slots=True)
class Outage:
    sim_down: float  # simulated time when the server stopped
    sim_up: float  # ... and when the executive was connected again
    frozen: float  # the executive's clock all that time
    result: Any  # what ``until`` returned

    @property
    def seconds(self) -> float:
        return self.sim_up - self.sim_down


def arrived(sim: Simulator, since: float) -> Callable[[Record], bool]:
    """A simulator log predicate: /FROG_response 2 (arrival) published at or after ``since``."""
    return lambda r: (
        r.direction == "out"
        and r.channel == "/FROG_response"
        and r.payload.get("data") == 2
        and r.t >= since
    )


def received(
    channel: str, *, where: Callable[[Any], bool] = lambda p: True, since: float = 0.0
) -> Callable[[Record], bool]:
    """A simulator log predicate: the executive's ``channel`` message, received from ``since``."""
    return lambda r: (
        r.direction == "in" and r.channel == channel and r.t >= since and where(r.payload)
    )
