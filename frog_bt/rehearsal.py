"""A rehearsal: the real executive against the built-in simulator, in one event loop.

``frog-bt demo`` runs one; end-to-end tests and benchmarks run many. The
simulator binds free loopback ports (or, with ``memory=True``, none: the links run over
:class:`~frog_bt.rosbridge.memory.MemoryWire` and :class:`~frog_bt.frontend.memory.MemoryNet`),
the executive is built with its links and runs on sim time with the simulator's
``/clock``, with the exit rules of a run (:mod:`frog_bt.runtime.exits`; ``once`` by
default) and, given a ``checkpoint``, its keeper (:mod:`frog_bt.runtime.keeper`); then
``prepare`` (if given) attaches recorders, telemetry or taps to the executive before it
connects::

    async with Rehearsal(scenario_from("default", {"speed": 200}), site=site) as r:
        await r.sim.wait_for(lambda rec: rec.channel == "/GotoWayPoint", 10)
        outcome = await r.finish()
"""

from __future__ import annotations

import asyncio
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Any

from frog_bt.behaviours import load_tree
from frog_bt.clock import Clock, SimClock
from frog_bt.config import Site
from frog_bt.frontend.link import FrontendLink
from frog_bt.model.frontend import EVENTS
from frog_bt.model.help import Help
from frog_bt.rosbridge.client import RosbridgeClient
from frog_bt.runtime.executive import Executive, Outcome
from frog_bt.runtime.exits import ExitRules
from frog_bt.runtime.keeper import Keeper
from frog_bt.runtime.observer import attach_all
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.simulator import Simulator
from frog_bt.tree.loader import LoadedTree

HOST = "127.0.0.1"


def free_udp_port(host: str = HOST) -> int:
    """A UDP port free right now (the executive's listen port must be known to the simulator)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def links_to(
    sim: Simulator, listen: tuple[str, int], clock: Clock, *, secret: str | None = None
) -> tuple[RosbridgeClient, FrontendLink]:
    """An executive's links to ``sim``: a rosbridge client of it (over memory when it serves
    there) and a front-end link listening on ``listen``."""
    wire = sim.wire
    if wire is not None:
        client = RosbridgeClient(wire.url, secret=secret, connect=wire.connect)
    else:
        client = RosbridgeClient(sim.via or f"ws://{HOST}:{sim.rosbridge_port}", secret=secret)
    link = FrontendLink(listen, (HOST, sim.frontend_port), clock, inbound=EVENTS, network=sim.net)
    return client, link


class Rehearsal:
    """The executive (``once`` by default) against a simulator of ``scenario``.

    Pass ``sim`` and ``listen`` to run a second executive against a simulator
    that is already running (a restart); it is then not stopped on exit. ``secret``: the
    executive's rosbridge secret; ``checkpoint`` (and ``fresh``): its keeper's file.
    ``memory``: a simulator of its own binds no socket (a running one is used as it is).
    """

    def __init__(
        self,
        scenario: Scenario | None,
        *,
        site: Site,
        tree: LoadedTree | None = None,
        sim: Simulator | None = None,
        listen: tuple[str, int] | None = None,
        sim_secret: str | None = None,
        prepare: Callable[[Executive], Any] | None = None,
        once: bool = True,
        checkpoint: Path | None = None,
        fresh: bool = False,
        secret: str | None = None,
        memory: bool = False,
    ) -> None:
        if sim is None:
            if scenario is None:
                raise ValueError("a scenario, or a running simulator and its listen address")
            listen = (HOST, 5006 if memory else free_udp_port())
            sim = Simulator(
                scenario,
                rosbridge_port=0,
                frontend_port=0,
                executive=listen,
                secret=sim_secret,
                memory=memory,
            )
            self.own_sim = True
        else:
            if listen is None:
                raise ValueError("a running simulator needs the listen address it sends to")
            self.own_sim = False
        self.sim = sim
        self.listen = listen
        self.site = site
        self.tree = tree or load_tree(site=site)
        self.prepare = prepare
        self.once = once
        self.keeper = Keeper(checkpoint, fresh=fresh) if checkpoint is not None else None
        self.secret = secret
        self.rules = ExitRules(once)
        self.task: asyncio.Task[Outcome] | None = None

    def _build(self) -> Executive:
        """The executive, handed links to the simulator."""
        assert self.listen is not None
        clock = SimClock()
        client, link = links_to(self.sim, self.listen, clock, secret=self.secret)
        return Executive(self.site, self.tree, clock, client, link, sim_time=True)

    async def __aenter__(self) -> Rehearsal:
        if self.own_sim:
            await self.sim.start()
        self.executive = self._build()
        if self.keeper is not None:  # first: what it takes up is recorded
            attach_all(self.executive, [self.keeper])
        attach_all(self.executive, [self.rules])
        if self.prepare is not None:
            self.prepare(self.executive)
        self.sim.follow(self._executive_time, self.executive.clock.sleep_until)
        self.task = asyncio.create_task(self.executive.run())
        return self

    def _executive_time(self) -> float | None:
        """The executive's clock while it runs and is connected (the simulator follows it)."""
        exe = self.executive
        if self.task is None or self.task.done() or not exe.client.link.connected:
            return None
        return exe.clock.now() if exe.clock.ready else None

    def lend_hands(self) -> None:
        """``done_by_hand`` does the step first, as a person would: the simulated robot is
        put on its charger (or off it), its fault fixed (frog-bt demo --console)."""
        self.executive.staff.by_hand = self.by_hand

    def by_hand(self, help_: Help) -> None:
        """Do what ``help_`` asks of a person in the simulator (published at its next
        step; the executive's staff apply ``done_by_hand`` once it sees it)."""
        self.sim.world.by_hand(help_.about.value)

    async def finish(self, timeout: float = 60.0) -> Outcome:
        """The executive's outcome (with ``once``: after one tour); TimeoutError after
        ``timeout`` wall seconds."""
        assert self.task is not None
        return await asyncio.wait_for(asyncio.shield(self.task), timeout)

    async def __aexit__(self, *exc: object) -> None:
        try:
            if self.task is not None:
                self.executive.stop("rehearsal over")
                try:
                    await asyncio.wait_for(self.task, 10)
                except (asyncio.CancelledError, KeyboardInterrupt, TimeoutError):
                    raise
                except BaseException as exc:  # a crash: the next start must not loop into it
                    if self.keeper is not None:
                        self.keeper.crashed(exc)
                    raise
        finally:
            self.sim.follow(None)
            if self.own_sim:
                await self.sim.stop()
