"""The front-end datagram protocol, sans-I/O (CONTRACT §2).

:class:`Endpoint` is one side of the link; the executive and the simulated
front end each hold one. It numbers what it originates (``seq``), acks what it
receives, resends what is not acked every ``resend_after`` seconds up to
``max_sends`` sends in all, and suppresses events whose ``seq`` it already
received within ``dedup_window`` seconds (acked again, not acted on). Datagrams
from any host but the peer's are dropped and counted.

A peer that restarts numbers from 1 again, and its new datagrams must not be
taken for duplicates of the old ones. A restart is recognised by a valid
message that is not a recent duplicate and whose ``seq`` is below the highest
seen: a ``frontend_idle`` (what a front end says first after starting; any of
``restart_types``), or ``seq`` 1. The seqs seen so far are then forgotten.

Time is passed in (``now``) and bytes are returned: no socket, no clock.
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

from frog_bt.codec import encode
from frog_bt.errors import DecodeError
from frog_bt.model.frontend import (
    DatagramDecoder,
    Envelope,
    FrontendMessage,
    decode_envelope,
    message_fields,
)
from frog_bt.text import fit

MAX_DATAGRAM = 8192
log = logging.getLogger(__name__)


def encode_datagram(type_: str, seq: int, fields: dict[str, Any] | None = None) -> bytes:
    """One datagram, at most :data:`MAX_DATAGRAM` bytes: a field too long to fit (a fault's
    message in a ``tour`` reason) is cut, marked, and logged; the message is never lost.
    ValueError only for what cannot be JSON (NaN)."""
    whole = {"type": type_, "seq": seq, **(fields or {})}
    data = encode(whole)
    if len(data) > MAX_DATAGRAM:
        size = len(data)
        _, data = fit(whole, encode, MAX_DATAGRAM)
        log.warning("%s datagram of %d bytes cut to %d (a field too long)", type_, size, len(data))
    return data


def decode_datagram(data: bytes) -> Envelope:
    """The ``type`` and ``seq`` of a datagram (JSON object, ``seq`` >= 0); or DecodeError."""
    if len(data) > MAX_DATAGRAM:
        raise DecodeError(f"datagram of {len(data)} bytes exceeds {MAX_DATAGRAM}")
    return decode_envelope(data)


@dataclass(slots=True)
class LinkStats:
    sent: int = 0
    resent: int = 0
    acked: int = 0
    unacked: int = 0  # commands given up on after max_sends
    received: int = 0
    duplicates: int = 0
    malformed: int = 0
    foreign: int = 0
    peer_restarts: int = 0  # the peer started numbering from 1 again


@dataclass(slots=True)
class _Pending:
    data: bytes
    message: FrontendMessage
    sends: int
    next_send: float
    first_sent: float = 0.0


@dataclass(frozen=True, slots=True)
class Received:
    """What one inbound datagram produced: a message to act on and/or an ack to send."""

    message: FrontendMessage | None = None
    reply: bytes | None = None
    error: DecodeError | None = None
    acked: FrontendMessage | None = None


@dataclass(slots=True)
class Endpoint:
    """One side of the front-end link.

    ``inbound`` is the table of message types this side acts on (events for the
    executive, commands for the front end). ``restart_types`` are the types a
    peer sends first after (re)starting (see the module docstring).
    """

    peer_host: str
    inbound: dict[str, type[FrontendMessage]]
    resend_after: float = 0.25
    max_sends: int = 8
    dedup_window: float = 10.0
    stats: LinkStats = field(default_factory=LinkStats)
    next_seq: int = 1
    restart_types: frozenset[str] = frozenset({"frontend_idle"})
    _pending: OrderedDict[int, _Pending] = field(default_factory=OrderedDict)
    _seen: OrderedDict[int, float] = field(default_factory=OrderedDict)
    _highest: int = 0  # highest seq of a valid message since the peer (re)started
    _decoder: DatagramDecoder = field(init=False)

    def __post_init__(self) -> None:
        self._decoder = DatagramDecoder(self.inbound)

    def send(self, message: FrontendMessage, now: float) -> bytes:
        """Datagram for a new message; it is resent by :meth:`poll` until acked."""
        seq = self.next_seq
        # Encode first: a message that cannot be encoded must not use up a seq.
        data = encode_datagram(message.type, seq, message_fields(message))
        self.next_seq += 1
        self._pending[seq] = _Pending(data, message, 1, now + self.resend_after, now)
        self.stats.sent += 1
        return data

    def receive(self, data: bytes, host: str, now: float) -> Received:
        """One datagram from ``host``, decoded in one pass (ack or message); one that does
        not decode whole is still acked when its ``type`` and ``seq`` are readable."""
        if host != self.peer_host:
            self.stats.foreign += 1
            return Received()
        if len(data) > MAX_DATAGRAM:
            self.stats.malformed += 1
            return Received(
                error=DecodeError(f"datagram of {len(data)} bytes exceeds {MAX_DATAGRAM}")
            )
        try:
            seq, message = self._decoder.decode(data)
        except DecodeError as exc:
            return self._malformed(data, exc, now)
        if message is None:  # an ack
            pending = self._pending.pop(seq, None)
            if pending is None:
                return Received()
            self.stats.acked += 1
            return Received(acked=pending.message)
        reply = encode_datagram("ack", seq)
        self._prune(now)
        restart = seq < self._highest and (
            message.type in self.restart_types or (seq == 1 and seq not in self._seen)
        )
        if seq in self._seen and not restart:
            self.stats.duplicates += 1
            return Received(reply=reply)
        if restart:
            # Only a valid message may reset the numbering: garbage must not.
            self.stats.peer_restarts += 1
            log.info(
                "peer %s restarted: %s seq %d after seq %d; forgetting seen seqs",
                self.peer_host,
                message.type,
                seq,
                self._highest,
            )
            self.forget_seen()
        self._seen[seq] = now
        self._highest = max(self._highest, seq)
        self.stats.received += 1
        return Received(message=message, reply=reply)

    def _malformed(self, data: bytes, error: DecodeError, now: float) -> Received:
        """A datagram that did not decode whole: acked (and its seq remembered) if its
        envelope reads, so the peer stops resending it; counted either way."""
        try:
            envelope = decode_envelope(data)
        except DecodeError as exc:
            self.stats.malformed += 1
            return Received(error=exc)
        if envelope.type == "ack":
            self.stats.malformed += 1
            return Received(error=error)
        if envelope.type not in self._decoder.table:
            error = DecodeError(f"unknown message type {envelope.type!r}"[:200], ("type",))
        self._prune(now)
        if envelope.seq in self._seen:
            self.stats.duplicates += 1
            return Received(reply=encode_datagram("ack", envelope.seq))
        self._seen[envelope.seq] = now
        self.stats.malformed += 1
        return Received(reply=encode_datagram("ack", envelope.seq), error=error)

    def _prune(self, now: float) -> None:
        while self._seen:
            seq, t = next(iter(self._seen.items()))
            if now - t <= self.dedup_window:
                break
            del self._seen[seq]

    def forget_seen(self) -> None:
        """Forget received seqs (the peer restarted and numbers from 1 again)."""
        self._seen.clear()
        self._highest = 0

    def poll(self, now: float) -> list[bytes]:
        """Datagrams to resend now; commands past ``max_sends`` are given up on."""
        out: list[bytes] = []
        for seq in list(self._pending):
            p = self._pending[seq]
            if p.next_send > now:
                continue
            if p.sends >= self.max_sends:
                del self._pending[seq]
                self.stats.unacked += 1
                log.warning(
                    "front end never acked %s (seq %d) after %d sends", p.message.type, seq, p.sends
                )
                continue
            p.sends += 1
            p.next_send = now + self.resend_after
            self.stats.resent += 1
            out.append(p.data)
        return out

    @property
    def next_deadline(self) -> float | None:
        return min((p.next_send for p in self._pending.values()), default=None)

    @property
    def pending(self) -> int:
        return len(self._pending)

    @property
    def oldest_pending(self) -> float | None:
        """When the oldest command still waiting for its ack was first sent."""
        for pending in self._pending.values():  # in order of sending
            return pending.first_sent
        return None
