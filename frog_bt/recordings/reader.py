"""The one decoder of a recording's channels: MCAP messages in, typed records out.

:class:`Reader` reads recordings (:func:`~frog_bt.recordings.mcapfile.open_recording`) in
log-time order and yields one record per message, decoded by the declaration its
channel comes from, never by hand:

==========================  ===========================================================
record                      channel, and what decodes it
==========================  ===========================================================
:class:`RobotInput`         an input topic of the wire table (by the site's role) or
                            ``/clock``: the role's :class:`~frog_bt.model.ros.RosType`
:class:`RobotCommand`       an output topic of the wire table (goal, approach, face
                            stream, dock): the role's RosType
:class:`FrontendIn`         ``/frontend/in``: an event of :data:`~frog_bt.model.frontend
                            .EVENTS`
:class:`FrontendOut`        ``/frontend/out``: a command of :data:`~frog_bt.model.frontend
                            .COMMANDS`
:class:`FrontendAck`        an ack on either (``/frontend/in``: the front end acked a
                            command; ``/frontend/out``: the executive acked an event)
:class:`Own`                ``/frog_bt/tick``, ``blame``, ``tree``, ``operator``,
                            ``alert``, ``links``, ``restored``: their Structs of
                            :mod:`frog_bt.model.channels`
:class:`Primed`             ``/frog_bt/primer``: its Struct, and its inputs decoded as
                            :class:`RobotInput` (at the time each was received)
:class:`Bad`                any of those that does not decode: channel and reason
==========================  ===========================================================

A message that does not decode is never dropped silently nor raised to the caller: it
is a :class:`Bad` record, and :attr:`Reader.tally` counts it by channel (the reasons of
the first :data:`BAD_KEPT` are kept). A channel the reader has no declaration for (a
topic the site does not name), or one the caller did not ask for (``only``), is not
decoded: its messages are counted in :attr:`Tally.unread`. A file damaged past reading
(a foreign MCAP whose index lies) ends with one :class:`Bad` record on channel ``""``.

Times are project-clock seconds (:func:`~frog_bt.model.channels.from_ns` of the log
time). Below the engine: the simulator reads recordings through this too.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Collection, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any, Literal

import msgspec

from frog_bt.codec import decode_error
from frog_bt.config import Site
from frog_bt.errors import DecodeError
from frog_bt.model import channels
from frog_bt.model.channels import FRONTEND_IN, FRONTEND_OUT, PRIMER, from_ns
from frog_bt.model.frontend import COMMANDS, EVENTS, DatagramDecoder, FrontendMessage
from frog_bt.model.ros import (
    ROS_TYPES,
    Diagnostics,
    FaceData,
    PersonDetections,
    Pose,
    RosType,
    TrackedPeople,
)
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.recordings.mcapfile import READ_ERRORS, RecordingFile

__all__ = [
    "BAD_KEPT",
    "CLOCK_ROLE",
    "Bad",
    "FrontendAck",
    "FrontendIn",
    "FrontendOut",
    "Own",
    "OwnMessage",
    "Primed",
    "Reader",
    "Record",
    "RobotCommand",
    "RobotInput",
    "RosValue",
    "Tally",
]

BAD_KEPT = 20  # bad messages whose reasons a tally keeps (all are counted)
CLOCK_ROLE = "clock"  # the role of /clock among the inputs (sim time only)

RosValue = Pose | Diagnostics | PersonDetections | FaceData | TrackedPeople | int | float | str
"""What a wire Struct's ``value()`` gives: what the leaves see."""
OwnMessage = (
    channels.Tick
    | channels.Blame
    | channels.Tree
    | channels.Operator
    | channels.Alert
    | channels.Doubt
    | channels.Fault
    | channels.Links
    | channels.Restored
)

# Errors a message can make decoding raise (DecodeError from the Structs; the others
# from a value() that computes on what it decoded): a bad message, not a crash.
_DECODE_ERRORS = (DecodeError, ValueError, TypeError, ArithmeticError)


class RobotInput(msgspec.Struct, frozen=True):
    """A message on a robot input (or ``/clock``): its role in the wire table, the wire
    Struct's value, and the rosbridge ``msg`` as recorded."""

    t: float
    topic: str
    role: str  # the wire table's role (``pose``, ``response``, ...) or CLOCK_ROLE
    value: RosValue
    raw: bytes

    def msg(self) -> dict[str, Any]:
        """The ``msg`` as a JSON object, for those who send it on (``sim --play``)."""
        return msgspec.json.decode(self.raw)  # type: ignore[no-any-return]


class RobotCommand(msgspec.Struct, frozen=True):
    """A command the executive sent to the robot: its role, the wire Struct's value, and
    the ``msg`` as sent (a JSON object: commands are compared in their wire form)."""

    t: float
    topic: str
    role: str  # ``goto``, ``approach``, ``icl``, ``dock``
    value: RosValue
    msg: dict[str, Any]
    raw: bytes


class FrontendIn(msgspec.Struct, frozen=True):
    """A datagram from the front end carrying an event (resends included: the same seq)."""

    t: float
    seq: int
    message: FrontendMessage
    raw: bytes


class FrontendOut(msgspec.Struct, frozen=True):
    """A datagram to the front end carrying a command (resends included: the same seq)."""

    t: float
    seq: int
    message: FrontendMessage
    raw: bytes


class FrontendAck(msgspec.Struct, frozen=True):
    """An ack: ``in`` from the front end (it got a command), ``out`` from the executive."""

    t: float
    direction: Literal["in", "out"]
    seq: int
    raw: bytes


class Own(msgspec.Struct, frozen=True):
    """A message of one of frog-bt's own channels (but the primer), as its Struct."""

    t: float
    channel: str
    message: OwnMessage


class Primed(msgspec.Struct, frozen=True):
    """A ``/frog_bt/primer``: what a rotated file carries from before it; ``inputs`` are
    its robot inputs decoded, each at the time it was received."""

    t: float
    primer: channels.Primer
    inputs: tuple[RobotInput, ...]
    bad: tuple[Bad, ...] = ()  # its inputs that did not decode (also yielded before it)


class Bad(msgspec.Struct, frozen=True):
    """A message that did not decode: where, why, and its bytes."""

    t: float
    channel: str  # the topic ("" when the file itself is damaged)
    reason: str  # the field's path and what was wrong (``data: expected `int`...``)
    raw: bytes = b""

    def line(self, start: float) -> str:
        """``/FROG_pose at +12.3 s: pose.position.x: expected `float`, got `str```."""
        return f"{self.channel or 'the file'} at +{self.t - start:.1f} s: {self.reason}"


Record = RobotInput | RobotCommand | FrontendIn | FrontendOut | FrontendAck | Own | Primed | Bad


@dataclass(slots=True)
class Tally:
    """What did not decode (all counted, the first ``keep`` kept) and what was not read."""

    keep: int = BAD_KEPT
    count: int = 0
    by_channel: Counter[str] = field(default_factory=Counter)
    first: list[Bad] = field(default_factory=list)
    unread: Counter[str] = field(default_factory=Counter)  # channels not decoded

    def add(self, bad: Bad) -> None:
        self.count += 1
        self.by_channel[bad.channel] += 1
        if len(self.first) < self.keep:
            self.first.append(bad)

    def lines(self, start: float) -> list[str]:
        """The kept reasons, one line each, times from ``start``."""
        return [bad.line(start) for bad in self.first]


_EVENTS = DatagramDecoder(EVENTS)
_COMMANDS = DatagramDecoder(COMMANDS)
_JSON = msgspec.json.Decoder()

Decode = Callable[[float, bytes], Record]


class Reader:
    """Reads recordings for one site (its topic names): :meth:`read` one file,
    :meth:`read_all` several in turn (a lead-in, then the file that continues it).

    ``only``: the channels to decode (the others are counted as unread, not decoded);
    all by default. :attr:`tally` counts bad and unread messages over every file read.
    """

    def __init__(
        self, site: Site, *, only: Collection[str] | None = None, keep: int = BAD_KEPT
    ) -> None:
        self.only = None if only is None else frozenset(only)
        self.tally = Tally(keep)
        self._inputs = {site.topic(role): role for role in INPUTS}
        self._inputs[CLOCK.name] = CLOCK_ROLE
        self._outputs = {site.topic(role): role for role in OUTPUTS}
        self._codecs: dict[str, RosType[Any]] = {
            role: topic.codec for role, topic in (*INPUTS.items(), *OUTPUTS.items())
        }
        self._codecs[CLOCK_ROLE] = CLOCK.codec

    def read_all(self, recordings: Iterable[RecordingFile]) -> Iterator[Record]:
        for recording in recordings:
            yield from self.read(recording)

    def read(self, recording: RecordingFile) -> Iterator[Record]:
        """Every message of ``recording`` as a record, in log-time order."""
        plan = self._plan(recording.types)
        unread = self.tally.unread
        add = self.tally.add
        messages = recording.messages()
        t = from_ns(recording.start)
        while True:
            try:
                topic, ns, data = next(messages)
            except StopIteration:
                return
            except READ_ERRORS as exc:
                bad = Bad(t, "", f"damaged past here: {type(exc).__name__}: {exc}"[:200])
                add(bad)
                yield bad
                return
            t = from_ns(ns)
            decode = plan.get(topic)
            if decode is None:
                unread[topic] += 1
                continue
            data = bytes(data)
            try:
                record = decode(t, data)
            except _DECODE_ERRORS as exc:
                record = Bad(t, topic, _reason(exc), data)
                add(record)
            else:
                if isinstance(record, Primed):
                    for bad in record.bad:
                        add(bad)
                        yield bad
            yield record

    # ------------------------------------------------------------ one decoder per channel

    def _plan(self, types: dict[str, str]) -> dict[str, Decode]:
        """Topic -> its decoder, for the channels of one file (and ``only``)."""
        plan: dict[str, Decode] = {}
        for topic, schema in types.items():
            if self.only is not None and topic not in self.only:
                continue
            decode = self._decoder(topic, schema)
            if decode is not None:
                plan[topic] = decode
        return plan

    def _decoder(self, topic: str, schema: str) -> Decode | None:
        role = self._inputs.get(topic)
        if role is not None:
            return self._ros(topic, schema, role, RobotInput)
        role = self._outputs.get(topic)
        if role is not None:
            return self._ros(topic, schema, role, RobotCommand)
        if topic == FRONTEND_IN:
            return _frontend_in
        if topic == FRONTEND_OUT:
            return _frontend_out
        if topic == PRIMER:
            return self._primer
        if topic in channels.TYPES:
            return lambda t, data: Own(t, topic, channels.decode(topic, data))
        return None

    def _ros(
        self, topic: str, schema: str, role: str, make: type[RobotInput | RobotCommand]
    ) -> Decode:
        """A robot topic's decoder: its role's RosType (what the executive decoded it
        with live); a channel whose schema names another ROS type is all bad."""
        codec = self._codecs[role]
        if schema in ROS_TYPES and schema != codec.name:
            reason = f"schema {schema}, but {topic} is {codec.name} in the wire table"

            def mismatched(t: float, data: bytes) -> Record:
                raise DecodeError(reason)

            return mismatched
        if make is RobotInput:
            value = codec.decode

            def robot_input(t: float, data: bytes) -> Record:
                return RobotInput(t, topic, role, value(data), data)

            return robot_input
        convert = codec.convert

        def robot_command(t: float, data: bytes) -> Record:
            try:
                msg = _JSON.decode(data)
            except msgspec.MsgspecError as exc:
                raise decode_error(exc) from None
            return RobotCommand(t, topic, role, convert(msg), msg, data)

        return robot_command

    def _primer(self, t: float, data: bytes) -> Primed:
        primer: channels.Primer = channels.decode(PRIMER, data)
        inputs: list[RobotInput] = []
        bad: list[Bad] = []
        for i, entry in enumerate(primer.inputs):
            role = self._inputs.get(entry.topic)
            if role is None or role == CLOCK_ROLE:
                continue  # not an input of this site's table: nothing to prime
            raw = bytes(entry.msg)
            try:
                inputs.append(
                    RobotInput(entry.t, entry.topic, role, self._codecs[role].decode(raw), raw)
                )
            except _DECODE_ERRORS as exc:
                bad.append(Bad(t, PRIMER, f"inputs[{i}] ({entry.topic}): {_reason(exc)}", raw))
        return Primed(t, primer, tuple(inputs), tuple(bad))


def _frontend_in(t: float, data: bytes) -> FrontendIn | FrontendAck:
    seq, message = _EVENTS.decode(data)
    return FrontendAck(t, "in", seq, data) if message is None else FrontendIn(t, seq, message, data)


def _frontend_out(t: float, data: bytes) -> FrontendOut | FrontendAck:
    seq, message = _COMMANDS.decode(data)
    return (
        FrontendAck(t, "out", seq, data) if message is None else FrontendOut(t, seq, message, data)
    )


def _reason(exc: Exception) -> str:
    text = str(exc) if isinstance(exc, DecodeError) else f"{type(exc).__name__}: {exc}"
    return text.splitlines()[0][:200] if text else type(exc).__name__
