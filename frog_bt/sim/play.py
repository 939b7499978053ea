"""The seed's recorded-data simulator (``frog-bt sim --play FILE.mcap``): a recorded
tour's robot-side inputs served over rosbridge on the recording's own clock, and its
front-end events sent over UDP, open loop.

:func:`load` reads a recording (after its lead-in file, as replay does: a tour file of
``--record DIR`` continues the idle file before it) into a :class:`Played`: the inputs
(every topic the executive subscribes to), the front end's events (``/frontend/in``
without its acks) and the commands the recorded executive sent. :class:`Comparison`
(sans-I/O) holds the commands a new executive sends against the recorded ones, each
stream in its own order (ROS topics; the front end's messages, resends dropped by seq;
the engagement meter apart, told as readings off by more than :data:`METER_TOLERANCE`:
where its 2 s windows fall moves with the executive's tick timing), and
describes the first difference in replay's domain terms. :class:`Player` is the I/O:
the built-in rosbridge server, the front end's UDP socket (it acks every command, as a
front end does: an ack is the protocol, not the content) and the time loop.

Open loop: nothing reacts to the commands. A new executive that acts as the recorded
one did sees the same world; one that acts otherwise sees it anyway (a goal it sends
elsewhere is "reached" when the recorded one was), and the comparison says where it
parted.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from frog_bt.config import Site
from frog_bt.observers.recording import FRONTEND_IN, FRONTEND_OUT
from frog_bt.sim import msgs
from frog_bt.sim.frontend_udp import Address, FrontendSocket
from frog_bt.sim.rosbridge_protocol import BridgeServer, Incoming
from frog_bt.sim.rosbridge_server import RosbridgeServer
from frog_bt.tools.replay import Command, chain, differences
from frog_bt.wire import CLOCK, INPUTS, OUTPUTS

log = logging.getLogger(__name__)

DT = 0.1  # simulated seconds per step of the time loop (a /clock each)
WAIT_POLL = 0.01  # wall seconds between looks for an executive's first subscription
SUBSCRIBE_GRACE = 0.3  # wall seconds for its other subscriptions, after the first
WAIT_MAX = 60.0  # wall seconds waiting for a rosbridge client before playing anyway
SEQ_PER_PASS = 1_000_000  # --loop: front-end seqs of pass n are the recorded ones + n x this
PASS_TAIL = 5.0  # recording seconds of /clock after its end before a pass counts as over
METER_TOLERANCE = 0.1  # engagement meter levels this close are the same reading


class PlayError(Exception):
    """The file cannot be played (not a recording, nothing of the robot in it)."""


def _without_stamp(msg: Any) -> Any:
    header = msg.get("header") if isinstance(msg, dict) else None
    if isinstance(header, dict) and "stamp" in header:
        msg = {**msg, "header": {k: v for k, v in header.items() if k != "stamp"}}
    return msg


@dataclass
class Played:
    files: list[str]
    start: float
    end: float
    inputs: list[tuple[float, str, dict[str, Any]]]  # (t, topic, msg), in time order
    events: list[tuple[float, bytes]]  # front-end datagrams to the executive
    commands: list[Command]  # what the recorded executive sent
    types: dict[str, str]  # the served topics' ROS types


def load(path: Path, site: Site) -> Played:
    """The recording at ``path`` (and its lead-in) as inputs, events and commands."""
    from frog_bt.tools.mcapfile import RecordingError

    try:
        recordings = chain(Path(path))
    except (RecordingError, OSError) as exc:
        raise PlayError(str(exc)) from None
    except Exception as exc:  # ReplayError: the lead-in is gone
        raise PlayError(str(exc)) from None
    served = {site.topic(role): t.type for role, t in INPUTS.items()}
    commands_on = {site.topic(role) for role in OUTPUTS}
    inputs: list[tuple[float, str, dict[str, Any]]] = []
    events: list[tuple[float, bytes]] = []
    commands: list[Command] = []
    seqs: set[Any] = set()
    start = end = None
    for recording in recordings:
        for topic, ns, data in recording.messages():
            t = ns / 1e9
            start = t if start is None else start
            end = t
            if topic in served or topic in commands_on or topic in (FRONTEND_IN,
                                                                    FRONTEND_OUT):
                try:
                    msg = json.loads(data)
                except ValueError:
                    continue
                if not isinstance(msg, dict):
                    continue
                if topic in served:
                    inputs.append((t, topic, msg))
                elif topic in commands_on:
                    commands.append(Command(t, topic, _without_stamp(msg)))
                elif msg.get("type") == "ack":
                    continue
                elif topic == FRONTEND_IN:
                    events.append((t, bytes(data)))
                else:
                    seq = msg.pop("seq", None)
                    if seq in seqs:
                        continue  # a resend
                    seqs.add(seq)
                    commands.append(Command(t, FRONTEND_OUT, msg))
    if not inputs or start is None or end is None:
        raise PlayError(f"{path}: no robot-side inputs in it (is it a frog-bt recording?)")
    types = {topic: type_ for topic, type_ in served.items()}
    types[CLOCK.name] = CLOCK.type
    return Played([str(r.path) for r in recordings], start, end, inputs, events, commands,
                  types)


@dataclass
class Comparison:
    """The commands received against the recorded ones, per stream, in order."""

    site: Site
    recorded: list[Command]
    start: float = 0.0
    received: int = 0  # commands but the engagement meter's
    differ: int = 0
    meter: int = 0  # engagement meter readings received
    meter_differ: int = 0  # ... off by more than METER_TOLERANCE (or one too many)
    first: str = ""  # the first difference, in domain terms
    _expected: dict[str, deque[Command]] = field(default_factory=dict)

    missed: int = 0  # recorded commands of earlier passes (--loop) never received
    beyond: int = 0  # received when the recording had no more of their stream

    def __post_init__(self) -> None:
        self.next_pass(0.0)

    def next_pass(self, offset: float) -> None:
        """Expect the recorded commands (again, ``offset`` seconds later: ``--loop``); what
        the last pass still expected was not received."""
        self.missed += self.missing
        self._expected = {}
        for command in self.recorded:
            later = Command(command.t + offset, command.channel, command.payload)
            self._expected.setdefault(_stream(command), deque()).append(later)

    def got(self, command: Command) -> str | None:
        """Take one command received; the description of the difference when it differs."""
        stream = _stream(command)
        queue = self._expected.get(stream)
        expected = queue.popleft() if queue else None
        if stream == "meter":  # a display, told apart: its windows move with tick timing
            self.meter += 1
            self.meter_differ += not (expected is not None and _same(expected, command))
            return None
        self.received += 1
        if expected is None:
            self.beyond += 1  # the recording has no more of these: nothing to hold it to
            return None
        if _same(expected, command):
            return None
        self.differ += 1
        text = differences(expected, command, self.site)
        if not self.first:
            self.first = f"at +{command.t - self.start:.1f} s: {text}"
        return text

    @property
    def missing(self) -> int:
        """Recorded commands (but meter readings) not received (yet)."""
        return sum(len(q) for s, q in self._expected.items() if s != "meter")

    def line(self) -> str:
        text = f"commands: {self.received} received, {self.differ} differ from the recording"
        if self.missing + self.missed:
            text += f", {self.missing + self.missed} recorded not received"
        if self.beyond:
            text += f", {self.beyond} past the recorded ones"
        if self.first:
            text += f"; first difference {self.first}"
        if self.meter:
            text += (f"; engagement meter: {self.meter} readings, {self.meter_differ} off by "
                     f"more than {METER_TOLERANCE:g} (its windows move with tick timing)")
        return text


def _stream(command: Command) -> str:
    """Commands are compared in order within their stream: ROS topics; the front end's
    engagement meter (one per window of face data: how many depends on where the windows
    fall, which the executive's tick timing moves); the other front-end messages."""
    if command.channel != FRONTEND_OUT:
        return "ros"
    return "meter" if command.payload.get("type") == "engagement" else "frontend"


def _same(expected: Command, got: Command) -> bool:
    if (expected.channel, expected.payload) == (got.channel, got.payload):
        return True
    if _stream(expected) == _stream(got) == "meter":  # a level, within the tolerance
        a, b = expected.payload.get("level"), got.payload.get("level")
        return (isinstance(a, int | float) and isinstance(b, int | float)
                and abs(a - b) <= METER_TOLERANCE)
    return False


class Player:
    """Serves a :class:`Played` recording; see the module docstring."""

    def __init__(self, played: Played, site: Site, *, host: str, rosbridge_port: int,
                 frontend_host: str, frontend_port: int, executive: Address,
                 speed: float = 1.0, loop: bool = False, secret: str | None = None,
                 on_difference: Callable[[str], None] | None = None,
                 wait_max: float = WAIT_MAX) -> None:
        self.played = played
        self.wait_max = wait_max
        self.speed = speed
        self.loop = loop
        self.now = played.start
        self.comparison = Comparison(site, played.commands, start=played.start)
        self.on_difference = on_difference
        self.rosbridge = RosbridgeServer(BridgeServer(secret, played.types), host,
                                         rosbridge_port, self._on_incoming, lambda: self.now)
        self.udp = FrontendSocket(frontend_host, frontend_port, executive, self._on_datagram)
        self.inputs_sent = 0
        self.events_sent = 0
        self.passes = 0  # times the recording was played to its end
        self.over = asyncio.Event()  # set at the recording's end (the first time)
        self.executive_seen = asyncio.Event()  # a client subscribed to /clock: playing
        self._seqs: set[Any] = set()
        self._task: asyncio.Task[None] | None = None

    async def start(self) -> None:
        await self.rosbridge.start()
        try:
            await self.udp.open()
        except OSError:
            await self.rosbridge.stop()
            raise
        self._task = asyncio.create_task(self._run(), name="frog-bt sim play")

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task
        await self.rosbridge.stop()
        self.udp.close()

    async def wait(self) -> None:
        """Until the time loop ends (only by :meth:`stop`, or a bug: then it raises)."""
        if self._task is not None:
            await asyncio.shield(self._task)

    async def _wait_for_executive(self) -> None:
        """Until a client subscribes to a topic it serves (then a moment for its other
        subscriptions): the recording starts for an executive, not before it; after
        ``wait_max`` wall seconds it starts anyway (a front end alone, say)."""
        loop = asyncio.get_running_loop()
        give_up = loop.time() + self.wait_max
        protocol = self.rosbridge.protocol
        while not any(protocol.subscribers(topic) for topic in self.played.types):
            if loop.time() >= give_up:
                log.warning("no rosbridge client after %.0f s: playing anyway", self.wait_max)
                break
            await asyncio.sleep(WAIT_POLL)
        else:
            await asyncio.sleep(SUBSCRIBE_GRACE)
        self.executive_seen.set()

    async def _run(self) -> None:
        await self._wait_for_executive()
        loop = asyncio.get_running_loop()
        played = self.played
        offset = 0.0  # each pass of --loop runs later: the clock never goes back
        length = played.end - played.start + PASS_TAIL + DT
        while True:
            i = j = 0
            t = played.start
            deadline = loop.time()
            while True:
                self.now = t + offset
                self.rosbridge.publish(CLOCK.name, msgs.clock(self.now))
                while i < len(played.inputs) and played.inputs[i][0] <= t:
                    _, topic, msg = played.inputs[i]
                    self.rosbridge.publish(topic, msg)
                    self.inputs_sent += 1
                    i += 1
                while j < len(played.events) and played.events[j][0] <= t:
                    self.udp.send(self._numbered(played.events[j][1]))
                    self.events_sent += 1
                    j += 1
                if t > played.end + PASS_TAIL:
                    break
                t += DT
                deadline += DT / self.speed
                now = loop.time()
                if now > deadline + 0.05:
                    deadline = now  # behind: the recording's time runs slower, no catching up
                await asyncio.sleep(max(0.0, deadline - now))
            self.passes += 1
            self.over.set()
            if not self.loop:
                # the recording is over: the clock goes on, so the executive's timers do
                await self._clock_on(t + offset)
                return
            offset += length  # the next pass starts where this one ended
            self.comparison.next_pass(offset)

    def _numbered(self, data: bytes) -> bytes:
        """A front-end event of a later pass numbered after the earlier ones (the same seq
        again would be taken for a resend)."""
        if not self.passes:
            return data
        try:
            msg = json.loads(data)
            msg["seq"] = int(msg["seq"]) + SEQ_PER_PASS * self.passes
        except (ValueError, KeyError, TypeError):
            return data
        return json.dumps(msg).encode()

    async def _clock_on(self, t: float) -> None:
        loop = asyncio.get_running_loop()
        deadline = loop.time()
        while True:
            self.now = t
            self.rosbridge.publish(CLOCK.name, msgs.clock(t))
            t += DT
            deadline += DT / self.speed
            await asyncio.sleep(max(0.0, deadline - loop.time()))

    def _on_incoming(self, incoming: Incoming) -> None:
        command = Command(self.now, incoming.topic, _without_stamp(incoming.msg))
        self._take(command)

    def _on_datagram(self, data: bytes, addr: Address) -> None:
        try:
            msg = json.loads(data)
        except ValueError:
            return
        if not isinstance(msg, dict) or msg.get("type") == "ack":
            return
        seq = msg.pop("seq", None)
        if isinstance(seq, int):
            self.udp.send(json.dumps({"type": "ack", "seq": seq}).encode())
        if seq in self._seqs:
            return  # a resend: acked again, compared once
        self._seqs.add(seq)
        self._take(Command(self.now, FRONTEND_OUT, msg))

    def _take(self, command: Command) -> None:
        text = self.comparison.got(command)
        if text is not None and self.comparison.differ == 1 and self.on_difference:
            self.on_difference(self.comparison.first)
