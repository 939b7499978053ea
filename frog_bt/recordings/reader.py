"""The one decoder of a recording's channels: MCAP messages in, the executive's events out.

:class:`Reader` reads recordings (:func:`~frog_bt.recordings.mcapfile.open_recording`) in
log-time order and yields ``(t, item)`` pairs: ``t`` the message's log time in
project-clock seconds (:func:`~frog_bt.model.channels.from_ns`), ``item`` what it holds,
decoded by the declaration its channel comes from, never by hand. The items are the
events observers hear live (:mod:`frog_bt.model.events`), the same Structs:

==============================  ======================================================
item                            from
==============================  ======================================================
:class:`RobotInput`             an input topic of the wire table (by the site's role),
                                or ``/clock``: its ``value`` is the role's RosType's
                                (``/clock``'s: the time it carries), ``raw`` the ``msg``
:class:`RobotCommand`           an output topic (goal, approach, face stream, dock):
                                the role's value and the ``msg`` sent (``goal``: None)
:class:`Datagram`               ``/frontend/in`` or ``/frontend/out``: every datagram,
                                acks and resends included, as it crossed
:class:`FrontendIn`             right after its datagram in: a new front-end event, as
                                the executive's link took it (the front-end protocol's
                                :class:`~frog_bt.frontend.protocol.Endpoint`: resends and
                                duplicates are not new, a restarted peer is seen)
:class:`FrontendOut`            right after its datagram out: a new command (a seq not
                                sent before; a resend is not one)
:class:`Ticked`, ...            ``/frog_bt/tick``, ``blame``, ``operator``, ``alert``,
                                ``doubt``, ``fault``, ``links``: the event recorded there
                                (:data:`~frog_bt.model.events.Recorded`; a recording
                                made before, by :mod:`frog_bt.recordings.legacy`)
``Tree``, ``Restored``          ``/frog_bt/tree``, ``/frog_bt/restored``: their Structs
                                (:mod:`frog_bt.model.channels`)
:class:`Primed`                 ``/frog_bt/primer``: its Struct and its inputs decoded
                                (it also primes the reader: its datagrams in and seqs out
                                were before the file, so their resends are not new)
:class:`Bad`                    a message that does not decode: channel and reason
==============================  ======================================================

A message that does not decode is never dropped silently nor raised to the caller: it
is a :class:`Bad` item (a datagram's comes after its :class:`Datagram`), and
:attr:`Reader.tally` counts it by channel (the reasons of the first :data:`BAD_KEPT` are
kept). A channel the reader has no declaration for (a topic the site does not name), or
one the caller did not ask for (``only``), is not decoded: its messages are counted in
:attr:`Tally.unread`. A file damaged past reading (a foreign MCAP whose index lies) ends
with one :class:`Bad` item on channel ``""``.

Below the engine: the simulator reads recordings through this too.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Collection, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import msgspec

from frog_bt.codec import decode_error
from frog_bt.config import Site
from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import channels
from frog_bt.model.channels import (
    EVENT_CHANNELS,
    FILE_TYPES,
    FRONTEND_IN,
    FRONTEND_OUT,
    PRIMER,
    Primer,
    Restored,
    Tree,
    from_ns,
)
from frog_bt.model.events import (
    Datagram,
    Event,
    FrontendIn,
    FrontendOut,
    RobotCommand,
    RobotInput,
)
from frog_bt.model.frontend import COMMANDS, EVENTS, DatagramDecoder
from frog_bt.model.ros import ROS_TYPES, RosType
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.recordings.legacy import legacy_decoder
from frog_bt.recordings.mcapfile import READ_ERRORS, RecordingFile

__all__ = ["BAD_KEPT", "CLOCK_ROLE", "Bad", "Item", "Primed", "Reader", "Tally"]

BAD_KEPT = 20  # bad messages whose reasons a tally keeps (all are counted)
CLOCK_ROLE = "clock"  # the role of /clock among the inputs (sim time only)
PEER = "recorded"  # the front end, as the reader's endpoint knows it (all it was told)

# Errors a message can make decoding raise (DecodeError from the Structs; the others
# from a value() that computes on what it decoded): a bad message, not a crash.
_DECODE_ERRORS = (DecodeError, ValueError, TypeError, ArithmeticError)


class Primed(msgspec.Struct, frozen=True):
    """A ``/frog_bt/primer``: what a rotated file carries from before it; ``inputs`` are
    its robot inputs decoded, each at the time it was received (one that does not decode
    is a :class:`Bad` item, before this one)."""

    primer: Primer
    inputs: tuple[RobotInput, ...]


class Bad(msgspec.Struct, frozen=True):
    """A message that did not decode: where, why, and its bytes."""

    t: float
    channel: str  # the topic ("" when the file itself is damaged)
    reason: str  # the field's path and what was wrong (``data: expected `int`...``)
    raw: bytes = b""

    def line(self, start: float) -> str:
        """``/FROG_pose at +12.3 s: pose.position.x: expected `float`, got `str```."""
        return f"{self.channel or 'the file'} at +{self.t - start:.1f} s: {self.reason}"


Item = Event | Tree | Restored | Primed | Bad
"""What the reader yields (with the message's time): an event, a file's Struct, a bad one."""


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


_COMMANDS = DatagramDecoder(COMMANDS)
_JSON = msgspec.json.Decoder()

Decode = Callable[[float, bytes], tuple[Item, ...]]


class Reader:
    """Reads recordings for one site (its topic names): :meth:`read` one file,
    :meth:`read_all` several in turn (a lead-in, then the file that continues it: one
    reader, so a resend across them is no new datagram).

    ``only``: the channels to decode (the others are counted as unread, not decoded);
    all by default. :attr:`tally` counts bad and unread messages over every file read;
    :attr:`roles` gives a robot topic's role in the wire table (``/clock``: ``clock``).
    """

    def __init__(
        self, site: Site, *, only: Collection[str] | None = None, keep: int = BAD_KEPT
    ) -> None:
        self.only = None if only is None else frozenset(only)
        self.tally = Tally(keep)
        self._inputs = {site.topic(role): role for role in INPUTS}
        self._inputs[CLOCK.name] = CLOCK_ROLE
        self._outputs = {site.topic(role): role for role in OUTPUTS}
        self.roles: dict[str, str] = {**self._inputs, **self._outputs}
        self._codecs: dict[str, RosType[Any]] = {
            role: topic.codec for role, topic in (*INPUTS.items(), *OUTPUTS.items())
        }
        self._codecs[CLOCK_ROLE] = CLOCK.codec
        # the front end's datagrams as the executive's link took them (CONTRACT §2)
        self._endpoint = Endpoint(PEER, EVENTS)
        self._sent: set[int] = set()  # seqs of commands out: a resend is no new command

    def read_all(self, recordings: Iterable[RecordingFile]) -> Iterator[tuple[float, Item]]:
        for recording in recordings:
            yield from self.read(recording)

    def read(self, recording: RecordingFile) -> Iterator[tuple[float, Item]]:
        """Every message of ``recording`` as ``(t, item)`` pairs, in log-time order."""
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
                yield t, bad
                return
            t = from_ns(ns)
            decode = plan.get(topic)
            if decode is None:
                unread[topic] += 1
                continue
            data = bytes(data)
            try:
                items = decode(t, data)
            except _DECODE_ERRORS as exc:
                items = (Bad(t, topic, _reason(exc), data),)
            for item in items:
                if type(item) is Bad:
                    add(item)
                yield t, item

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
            return self._robot_input(topic, schema, role)
        role = self._outputs.get(topic)
        if role is not None:
            return self._robot_command(topic, schema, role)
        if topic == FRONTEND_IN:
            return self._frontend_in
        if topic == FRONTEND_OUT:
            return self._frontend_out
        if topic == PRIMER:
            return self._primer
        if topic in FILE_TYPES:
            return lambda t, data: (channels.decode(topic, data),)
        if topic in EVENT_CHANNELS.values():
            old = legacy_decoder(schema)
            if old is not None:  # a recording made before: the event from its old shape
                return lambda t, data: (old(t, data),)
            return lambda t, data: (channels.decode_event(data),)
        return None

    def _codec(self, topic: str, schema: str, role: str) -> RosType[Any] | str:
        """A robot topic's RosType (what the executive decoded it with live); a channel
        whose schema names another ROS type is all bad: why."""
        codec = self._codecs[role]
        if schema in ROS_TYPES and schema != codec.name:
            return f"schema {schema}, but {topic} is {codec.name} in the wire table"
        return codec

    def _robot_input(self, topic: str, schema: str, role: str) -> Decode:
        codec = self._codec(topic, schema, role)
        if isinstance(codec, str):
            return _all_bad(codec)
        value = codec.decode

        def robot_input(t: float, data: bytes) -> tuple[Item, ...]:
            return (RobotInput(t, topic, value(data), msgspec.Raw(data)),)

        return robot_input

    def _robot_command(self, topic: str, schema: str, role: str) -> Decode:
        codec = self._codec(topic, schema, role)
        if isinstance(codec, str):
            return _all_bad(codec)
        convert = codec.convert

        def robot_command(t: float, data: bytes) -> tuple[Item, ...]:
            try:
                msg = _JSON.decode(data)
            except msgspec.MsgspecError as exc:
                raise decode_error(exc) from None
            return (RobotCommand(t, role, topic, convert(msg), msg),)

        return robot_command

    def _frontend_in(self, t: float, data: bytes) -> tuple[Item, ...]:
        """A datagram in, through the front-end protocol as the executive's link took it:
        a new event after it, a duplicate or an ack nothing more, a bad one a Bad."""
        datagram = Datagram(t, "in", data)
        received = self._endpoint.receive(data, PEER, t)
        if received.message is not None:
            return datagram, FrontendIn(t, received.message)
        if received.error is not None:
            return datagram, Bad(t, FRONTEND_IN, _reason(received.error), data)
        return (datagram,)

    def _frontend_out(self, t: float, data: bytes) -> tuple[Item, ...]:
        """A datagram out: a new command after it (a resend has a seq sent before)."""
        datagram = Datagram(t, "out", data)
        try:
            seq, message = _COMMANDS.decode(data)
        except DecodeError as exc:
            return datagram, Bad(t, FRONTEND_OUT, _reason(exc), data)
        if message is None or seq in self._sent:
            return (datagram,)
        self._sent.add(seq)
        return datagram, FrontendOut(t, message)

    def _primer(self, t: float, data: bytes) -> tuple[Item, ...]:
        primer: Primer = channels.decode(PRIMER, data)
        for text in primer.frontend_in:  # seen live before the file: their resends not new
            self._endpoint.receive(text.encode(), PEER, t)
        self._sent.update(primer.frontend_out_seqs)
        inputs: list[RobotInput] = []
        bad: list[Item] = []
        for i, entry in enumerate(primer.inputs):
            role = self._inputs.get(entry.topic)
            if role is None or role == CLOCK_ROLE:
                continue  # not an input of this site's table: nothing to prime
            raw = bytes(entry.msg)
            try:
                value = self._codecs[role].decode(raw)
            except _DECODE_ERRORS as exc:
                bad.append(Bad(t, PRIMER, f"inputs[{i}] ({entry.topic}): {_reason(exc)}", raw))
            else:
                inputs.append(RobotInput(entry.t, entry.topic, value, entry.msg))
        return *bad, Primed(primer, tuple(inputs))


def _all_bad(reason: str) -> Decode:
    def mismatched(t: float, data: bytes) -> tuple[Item, ...]:
        raise DecodeError(reason)

    return mismatched


def _reason(exc: Exception) -> str:
    text = str(exc) if isinstance(exc, DecodeError) else f"{type(exc).__name__}: {exc}"
    return text.splitlines()[0][:200] if text else type(exc).__name__
