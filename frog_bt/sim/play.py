"""The seed's recorded-data simulator (``frog-bt sim --play FILE.mcap``): a recorded
tour's robot-side inputs served over rosbridge on the recording's own clock, and its
front-end events sent over UDP, open loop.

:func:`load` reads a recording into a :class:`Played`, through the one decoder of
recordings (:class:`~frog_bt.recordings.reader.Reader`), as the executive's events it
gives back: the inputs (every topic the executive subscribes to), the front end's new
events (what the recorded executive's link took as new: no acks, no resends) and the
commands the recorded executive sent (ROS outputs; new front-end commands: no acks, no
resends). A message that does not decode is not played: it is counted, and the
summary says how many and the first few. A tour file of ``--record DIR`` is read after
the idle file it continues (its ``lead_in``, as replay does); a first file that starts
with a ``/frog_bt/primer`` (an idle file of ``--record DIR``) gives its inputs first, at
its start: the latest message of each input from before the file, which a robot that
publishes on change would not send again. The primer's datagrams are not played (the
live executive had them; a new one never asked for them).

:class:`Player` is the I/O: the built-in rosbridge server, the front end's UDP socket
and the time loop. The datagrams are the front-end protocol's
(:mod:`frog_bt.frontend.protocol`): each event is sent once, numbered from 1 over the
whole play (a later pass of ``--loop`` goes on numbering); each command is taken by the
front end's :class:`~frog_bt.frontend.protocol.Endpoint`, which acks it, as a front end
does (an ack is the protocol, not the content), and tells a resend from a new one. The
commands received go to a :class:`~frog_bt.sim.comparison.Comparison` (sans-I/O), which
holds them against the recorded ones and tells the first difference in replay's domain terms.

Open loop: nothing reacts to the commands. A new executive that acts as the recorded
one did sees the same world; one that acts otherwise sees it anyway (a goal it sends
elsewhere is "reached" when the recorded one was), and the comparison says where it
parted.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import msgspec

import frog_bt.sim.msgs as msgs
from frog_bt.config import Site
from frog_bt.errors import FrogError
from frog_bt.frontend.protocol import Endpoint, encode_datagram
from frog_bt.model.channels import FRONTEND_IN, FRONTEND_OUT, PRIMER, from_ns
from frog_bt.model.events import FrontendIn, FrontendOut, RobotCommand, RobotInput
from frog_bt.model.frontend import COMMANDS, FrontendMessage, message_fields
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.recordings.commands import Command, chain, plain, without_stamp
from frog_bt.recordings.reader import Primed, Reader
from frog_bt.sim.comparison import Comparison
from frog_bt.sim.frontend_udp import Address, FrontendSocket
from frog_bt.sim.rosbridge_protocol import BridgeServer, Incoming
from frog_bt.sim.rosbridge_server import RosbridgeServer

log = logging.getLogger(__name__)

DT = 0.1  # simulated seconds per step of the time loop (a /clock each)
WAIT_POLL = 0.01  # wall seconds between looks for an executive's first subscription
SUBSCRIBE_GRACE = 0.3  # wall seconds for its other subscriptions, after the first
WAIT_MAX = 60.0  # wall seconds waiting for a rosbridge client before playing anyway
PASS_TAIL = 5.0  # recording seconds of /clock after its end before a pass counts as over
BAD_TOLD = 3  # bad messages whose reasons the summary tells (all are counted)
EXECUTIVE = "executive"  # the peer of the player's endpoint: whoever sends to its socket


class PlayError(FrogError):
    """The file cannot be played (not a recording, its lead-in gone, nothing of the robot
    in it)."""


@dataclass
class Played:
    """A recording as the player serves it; times are the recording's, in seconds."""

    files: list[str]  # the files read, the lead-in first
    start: float
    end: float
    inputs: list[tuple[float, str, dict[str, Any]]]  # (t, topic, msg), in time order
    events: list[tuple[float, FrontendMessage]]  # front-end events to the executive
    commands: list[Command]  # what the recorded executive sent
    types: dict[str, str]  # the served topics' ROS types
    bad: int = 0  # recorded messages that did not decode: not played
    bad_first: list[str] = field(default_factory=list)  # the first few: where and why


def load(path: Path, site: Site) -> Played:
    """The recording at ``path`` (after its lead-in) as inputs, events and commands;
    PlayError when it is not a recording, its lead-in is gone or it has no input."""
    try:
        recordings = chain(Path(path))
    except (FrogError, OSError) as exc:  # not a recording; its lead-in is gone
        raise PlayError(str(exc)) from exc
    served = {site.topic(role): t.type for role, t in INPUTS.items()}
    commands_on = {site.topic(role) for role in OUTPUTS}
    reader = Reader(site, only={*served, *commands_on, FRONTEND_IN, FRONTEND_OUT, PRIMER})
    inputs: list[tuple[float, str, dict[str, Any]]] = []
    events: list[tuple[float, FrontendMessage]] = []
    commands: list[Command] = []
    for recording in recordings:
        for t, item in reader.read(recording):
            match item:
                case RobotInput():
                    inputs.append((t, item.topic, _msg(item)))
                case RobotCommand():
                    commands.append(Command(t, item.topic, without_stamp(item.msg)))
                case FrontendIn(message=message):
                    events.append((t, message))
                case FrontendOut(message=message):
                    fields = plain({"type": message.type, **message_fields(message)})
                    commands.append(Command(t, FRONTEND_OUT, fields))
                case Primed() if recording is recordings[0] and not inputs:
                    # the inputs' latest messages from before the file, given at its start
                    inputs.extend((t, i.topic, _msg(i)) for i in item.inputs)
    if not inputs:
        raise PlayError(f"{path}: no robot-side inputs in it (is it a frog-bt recording?)")
    tally = reader.tally
    start = from_ns(recordings[0].start)
    if tally.count:
        log.warning(
            "%d recorded message(s) did not decode and are not played; first: %s",
            tally.count,
            tally.first[0].line(start),
        )
    types = dict(served)
    types[CLOCK.name] = CLOCK.type
    return Played(
        [str(r.path) for r in recordings],
        start,
        from_ns(recordings[-1].end),
        inputs,
        events,
        commands,
        types,
        tally.count,
        tally.lines(start)[:BAD_TOLD],
    )


class Player:
    """Serves a :class:`Played` recording; see the module docstring."""

    def __init__(
        self,
        played: Played,
        site: Site,
        *,
        host: str,
        rosbridge_port: int,
        frontend_host: str,
        frontend_port: int,
        executive: Address,
        speed: float = 1.0,
        loop: bool = False,
        secret: str | None = None,
        on_difference: Callable[[str], None] | None = None,
        wait_max: float = WAIT_MAX,
    ) -> None:
        self.played = played
        self.wait_max = wait_max
        self.speed = speed
        self.loop = loop
        self.now = played.start
        self.comparison = Comparison(site, played.commands, start=played.start)
        self.on_difference = on_difference
        self.rosbridge = RosbridgeServer(
            BridgeServer(secret, played.types),
            host,
            rosbridge_port,
            self._on_incoming,
            lambda: self.now,
        )
        self.udp = FrontendSocket(frontend_host, frontend_port, executive, self._on_datagram)
        self.inputs_sent = 0
        self.events_sent = 0
        self.passes = 0  # times the recording was played to its end
        self.over = asyncio.Event()  # set at the recording's end (the first time)
        self.executive_seen = asyncio.Event()  # a client subscribed to /clock: playing
        # the front end's side of the link: commands in (acked, resends told), events out
        self.endpoint = Endpoint(EXECUTIVE, COMMANDS)
        self._seqs = itertools.count(1)  # the events' seqs, over every pass
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

    def summary(self) -> str:
        """``played 3893 inputs and 11 front-end events; commands: ...`` (so far)."""
        passes = f" ({self.passes} whole passes)" if self.loop else ""
        bad = ""
        if self.played.bad:
            bad = (
                f"; {self.played.bad} recorded message(s) did not decode, not played "
                f"({'; '.join(self.played.bad_first)})"
            )
        return (
            f"played {self.inputs_sent} inputs and {self.events_sent} front-end "
            f"events{passes}; {self.comparison.line()}{bad}"
        )

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
                    self.rosbridge.publish(topic, restamped(msg, offset))
                    self.inputs_sent += 1
                    i += 1
                while j < len(played.events) and played.events[j][0] <= t:
                    self.udp.send(self._datagram(played.events[j][1]))
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

    def _datagram(self, message: FrontendMessage) -> bytes:
        """A front-end event's datagram, numbered after every one sent before (a later
        pass's too: the same seq again would be taken for a resend)."""
        return encode_datagram(message.type, next(self._seqs), message_fields(message))

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
        command = Command(self.now, incoming.topic, without_stamp(incoming.msg))
        self._take(command)

    def _on_datagram(self, data: bytes, addr: Address) -> None:
        """A datagram from the executive, through the front end's endpoint: acked, and a
        new command compared (a resend is acked again, compared once)."""
        received = self.endpoint.receive(data, EXECUTIVE, self.now)
        if received.reply is not None:
            self.udp.send(received.reply)
        message = received.message
        if message is not None:
            fields = plain({"type": message.type, **message_fields(message)})
            self._take(Command(self.now, FRONTEND_OUT, fields))

    def _take(self, command: Command) -> None:
        text = self.comparison.got(command)
        if text is not None and self.comparison.differ == 1 and self.on_difference:
            self.on_difference(self.comparison.first)


def _msg(received: RobotInput) -> dict[str, Any]:
    """The rosbridge ``msg`` of a recorded input, as a JSON object (to send it on)."""
    raw = received.raw
    msg: dict[str, Any] = msgspec.json.decode(raw) if raw is not None else {}
    return msg


def restamped(msg: dict[str, Any], offset: float) -> dict[str, Any]:
    """``msg`` with its header's stamp ``offset`` seconds later, in the same shape
    (``--loop``: a later pass keeps its stamps in step with its ``/clock``); ``msg``
    itself when there is nothing to move."""
    header = msg.get("header")
    if not offset or not isinstance(header, dict) or not isinstance(header.get("stamp"), dict):
        return msg
    stamp = header["stamp"]
    for secs, nsecs in (("secs", "nsecs"), ("sec", "nanosec")):  # ROS 1, ROS 2
        s, n = stamp.get(secs), stamp.get(nsecs)
        if isinstance(s, int) and isinstance(n, int):
            ns = s * 1_000_000_000 + n + round(offset * 1e9)
            moved = {**stamp, secs: ns // 1_000_000_000, nsecs: ns % 1_000_000_000}
            return {**msg, "header": {**header, "stamp": moved}}
    return msg
