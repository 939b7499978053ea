"""The simulator: world, rosbridge server, front end and the clock, wired together.

The simulator is the master of time. It owns a
:class:`~frog_bt.clock.ManualClock` that starts at the scenario's
``start_time``; each step advances the world by ``dt`` simulated seconds,
publishes ``/clock`` and whatever is due, and lets the front end send what is
due. The time loop paces steps to the wall clock by the speed factor
(``speed: 50`` = 50x real time); when the process cannot keep up, simulated
time simply runs slower (it never jumps to catch up).

A simulator can *follow* its executive (:meth:`Simulator.follow`): it then
runs at most ``lead`` simulated seconds ahead of the executive's clock, and
waits (re-publishing ``/clock``) until the executive catches up. A loaded
machine then slows the whole rehearsal down instead of changing what the
executive sees: the same tour at any load. :meth:`pause` holds the world
still (a test reconnecting its executive, say).

With ``memory=True`` nothing binds a socket: the rosbridge server serves a
:class:`~frog_bt.rosbridge.memory.MemoryWire` (:attr:`Simulator.wire`) and the front end
a :class:`~frog_bt.frontend.memory.MemoryNet` (:attr:`Simulator.net`), which the
executive's links are then built on (:mod:`frog_bt.rehearsal`).

Tests can also skip the time loop (``await sim.start(run_clock=False)``) and
move the world by hand with :meth:`Simulator.step` / :meth:`Simulator.advance`.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import random
from collections.abc import Awaitable, Callable, Mapping
from typing import Any

import frog_bt.sim.msgs as msgs
from frog_bt.clock import ManualClock
from frog_bt.frontend.memory import MemoryNet
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.rosbridge.memory import MemoryWire
from frog_bt.sim.frontend import FrontendModel
from frog_bt.sim.frontend_udp import Address, FrontendSocket
from frog_bt.sim.rosbridge_protocol import BridgeServer, Incoming
from frog_bt.sim.rosbridge_server import RosbridgeServer
from frog_bt.sim.rosbridge_via import RosbridgeVia
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.site import PoiPose, load_pois
from frog_bt.sim.traffic import MessageLog, Predicate, Record
from frog_bt.sim.world import World

log = logging.getLogger(__name__)

MAX_LAG = 0.05  # wall seconds behind schedule before the loop stops trying to catch up
FOLLOW_POLL = 0.001  # wall seconds between looks at a lagging executive
REPUBLISH_AFTER = 0.05  # wall seconds waiting before /clock is published again


class Simulator:
    """The simulated robot (rosbridge server) and front end (UDP) of one scenario."""

    def __init__(
        self,
        scenario: Scenario,
        *,
        host: str = "127.0.0.1",
        rosbridge_port: int = 9090,
        frontend_port: int = 5005,
        executive: tuple[str, int] = ("127.0.0.1", 5006),
        pois: Mapping[str, PoiPose] | None = None,
        secret: str | None = None,
        frontend_host: str | None = None,
        via: str | None = None,
        memory: bool = False,
    ) -> None:
        self.scenario = scenario
        self.speed = scenario.speed
        self._follow: Callable[[], float | None] | None = None
        self._lead = 0.5
        self._wait_until: Callable[[float], Awaitable[Any]] | None = None
        self._paused = False
        self.pois = dict(pois) if pois is not None else load_pois()
        self.world = World(scenario, self.pois)
        self.clock = ManualClock(self.world.now)
        self.log = MessageLog()
        types = {t.name: t.type for t in (*INPUTS.values(), *OUTPUTS.values(), CLOCK)}
        self.bridge = BridgeServer(secret, types)
        self.via = via
        # in memory: no socket at all; the executive connects with wire.connect and
        # binds its front-end link on net (frog_bt.rosbridge.memory, frog_bt.frontend.memory)
        self.wire = MemoryWire(host) if memory and via is None else None
        self.net = MemoryNet() if memory else None
        self._rosbridge: RosbridgeServer | RosbridgeVia
        if via is None:
            self._rosbridge = RosbridgeServer(
                self.bridge, host, rosbridge_port, self._on_incoming, self.clock.now, self.wire
            )
        else:  # the robot as a client of an existing server (secret: to authenticate)
            robot = {t.name: t.type for t in (*INPUTS.values(), CLOCK)}
            commands = {t.name: t.type for t in OUTPUTS.values()}
            self._rosbridge = RosbridgeVia(via, robot, commands, self._on_incoming, secret=secret)
        self.frontend = FrontendModel(
            scenario, executive[0], self._visitor_says_yes, self._on_frontend_traffic
        )
        self._udp = FrontendSocket(
            frontend_host or host,
            frontend_port,
            (executive[0], executive[1]),
            self._on_datagram,
            self.net,
        )
        self._loop_task: asyncio.Task[None] | None = None
        self._dropped: dict[str, float] = {}  # topic -> simulated time its drop-out ends
        self._loss_rng = random.Random(scenario.seed)
        self.datagrams_lost = 0
        self._started = False

    # ------------------------------------------------------------ lifecycle

    @property
    def rosbridge_port(self) -> int:
        return self._rosbridge.port

    @property
    def frontend_port(self) -> int:
        return self._udp.port

    @property
    def addresses(self) -> dict[str, list[Address]]:
        """What the simulator listens on: ``rosbridge`` (TCP) and ``frontend`` (UDP)."""
        udp = self._udp.address
        return {"rosbridge": self._rosbridge.addresses, "frontend": [udp] if udp else []}

    @property
    def running(self) -> bool:
        return self._loop_task is not None and not self._loop_task.done()

    async def wait_clock_stopped(self) -> None:
        """Return when the time loop ends (only by :meth:`stop`, or a bug: then it raises)."""
        if self._loop_task is not None:
            await asyncio.shield(self._loop_task)

    async def start(self, *, run_clock: bool = True) -> None:
        """Bind the rosbridge server and the front-end socket; start the time loop."""
        await self._rosbridge.start()
        try:
            await self._udp.open()
        except OSError:
            await self._rosbridge.stop()
            raise
        if not self._started:
            self.frontend.start(self.clock.now())
            self._started = True
        if run_clock:
            self._loop_task = asyncio.create_task(self._run(), name="frog-bt sim clock")

    async def stop(self) -> None:
        """Stop the time loop, drop the clients, close the sockets."""
        task, self._loop_task = self._loop_task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
        await self._rosbridge.stop()
        self._udp.close()

    async def stop_rosbridge(self) -> None:
        """Drop all rosbridge clients and stop listening; the world keeps running.
        (Only for the simulator's own server: ``via`` a server, restart that server.)"""
        if self.via is not None:
            raise RuntimeError(f"the simulator serves no rosbridge: it is a client of {self.via}")
        await self._rosbridge.stop()

    async def start_rosbridge(self) -> None:
        """Listen again, on the same port."""
        await self._rosbridge.start()

    def restart_frontend(self) -> None:
        """The front end restarts now (as a scenario ``frontend.restarts`` time would)."""
        for data in self.frontend.restart(self.world.now):
            self._send_udp(data)

    def silence_frontend(self, seconds: float) -> None:
        """The front end hangs for ``seconds`` of simulated time from now (``inf``: for ever)."""
        self.frontend.silence(self.world.now, self.world.now + seconds)

    # ------------------------------------------------------------ time

    def follow(
        self,
        executive_time: Callable[[], float | None] | None,
        wait_until: Callable[[float], Awaitable[Any]] | None = None,
        lead: float = 0.5,
    ) -> None:
        """Run at most ``lead`` simulated seconds ahead of ``executive_time()`` (the
        executive's clock; None while it does not follow, e.g. disconnected).
        ``wait_until(t)`` resolves once the executive's clock reaches ``t`` (without it
        the simulator looks every millisecond)."""
        self._follow = executive_time
        self._wait_until = wait_until
        self._lead = lead

    def pause(self, paused: bool = True) -> None:
        """Hold simulated time still (False: let it run again)."""
        self._paused = paused

    def _waiting(self) -> bool:
        if self._paused:
            return True
        t = self._follow() if self._follow is not None else None
        return t is not None and self.world.now - t > self._lead

    async def _run(self) -> None:
        loop = asyncio.get_running_loop()
        deadline = loop.time()
        while True:
            if self._waiting():
                waited = 0.0
                while self._waiting():
                    if self._wait_until is not None and not self._paused:
                        target = self.world.now - self._lead
                        try:  # asyncio.timeout: a cancel is never swallowed (3.11 wait_for)
                            async with asyncio.timeout(REPUBLISH_AFTER):
                                await self._wait_until(target)
                        except TimeoutError:
                            waited = REPUBLISH_AFTER
                    else:
                        await asyncio.sleep(FOLLOW_POLL)
                        waited += FOLLOW_POLL
                    if waited >= REPUBLISH_AFTER and not self._paused:
                        # the executive may have missed it (it was reconnecting, say)
                        self._publish(CLOCK.name, msgs.clock(self.world.now), logged=False)
                        waited = 0.0
                deadline = loop.time()
            try:
                self.step()
            except Exception:
                log.exception("simulation step failed; the clock stops")
                raise
            deadline += self.scenario.dt / self.speed
            now = loop.time()
            if now > deadline + MAX_LAG:
                deadline = now  # behind: simulated time runs slower, no catching up
            await asyncio.sleep(max(0.0, deadline - now))

    def step(self) -> None:
        """One step of ``dt`` simulated seconds, without pacing."""
        outputs = self.world.step(self.scenario.dt)
        self.clock.set(self.world.now)
        self._publish(CLOCK.name, msgs.clock(self.world.now), logged=False)
        for topic, msg in outputs:
            self._publish(topic, msg)
        for data in self.frontend.step(self.world.now):
            self._send_udp(data)

    def advance(self, seconds: float) -> None:
        """Step by hand until ``seconds`` more of simulated time have passed."""
        end = self.world.elapsed + seconds - 1e-9
        while self.world.elapsed < end:
            self.step()

    # ------------------------------------------------------------ traffic

    def drop(self, topic: str, seconds: float) -> None:
        """A sensor drop-out: ``topic`` is not published for ``seconds`` of simulated time."""
        self._dropped[topic] = self.world.now + seconds

    def _publish(self, topic: str, msg: dict[str, Any], logged: bool = True) -> None:
        until = self._dropped.get(topic)
        if until is not None:
            if self.world.now < until:
                return
            del self._dropped[topic]
        if logged:
            self.log.append(Record(self.world.now, "ros", "out", topic, msg))
        self._rosbridge.publish(topic, msg)

    def _on_incoming(self, incoming: Incoming) -> None:
        self.log.append(Record(self.world.now, "ros", "in", incoming.topic, incoming.msg))
        for topic, msg in self.world.handle(incoming.topic, incoming.msg):
            self._publish(topic, msg)

    def _on_datagram(self, data: bytes, addr: Address) -> None:
        if self._lost():
            return
        for reply in self.frontend.receive(data, addr[0], self.world.now):
            self._send_udp(reply)

    def _send_udp(self, data: bytes) -> None:
        if not self._lost():
            self._udp.send(data)

    def _lost(self) -> bool:
        """Scenario ``frontend.loss``: this datagram is lost (seeded, so runs repeat)."""
        loss = self.scenario.frontend.loss
        if loss and self._loss_rng.random() < loss:
            self.datagrams_lost += 1
            return True
        return False

    def _on_frontend_traffic(self, direction: str, channel: str, fields: dict[str, Any]) -> None:
        self.log.append(Record(self.world.now, "frontend", direction, channel, fields))
        self.world.on_frontend(direction, channel, fields)

    def _visitor_says_yes(self) -> bool:
        visitor = self.world.current_visitor
        return visitor is None or visitor.spec.answer == "positive"

    # ------------------------------------------------------------ for tests

    def received(self, channel: str | None = None, side: str | None = None) -> list[Record]:
        """What the executive sent (log records with direction ``in``)."""
        return self.log.received(channel, side)

    async def wait_for(self, predicate: Predicate, timeout: float) -> Record:
        """The first log record satisfying ``predicate``; TimeoutError after ``timeout`` wall s."""
        return await self.log.wait_for(predicate, timeout)
