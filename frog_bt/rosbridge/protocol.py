"""rosbridge v2 JSON protocol, sans-I/O: text in, typed values out, text to send.

No sockets and no clock here. :class:`Session` keeps what a client has
advertised and subscribed, so that after a reconnect everything can be sent
again, and holds outbound publishes in a bounded queue while the link is down
(the oldest are dropped and counted: memory never grows without bound).

Inbound frames decode to :class:`Publish`, :class:`Status` or :class:`OtherOp`
(any op a client does not act on, ignored by the caller); malformed frames raise
:class:`~frog_bt.errors.DecodeError`.
"""

from __future__ import annotations

import hashlib
import itertools
import math
import secrets
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import msgspec

from frog_bt.codec import decoder, encode
from frog_bt.errors import DecodeError

MAX_FRAME_BYTES = 1 << 20  # rosbridge's own default max message size is larger; ours is a guard


@dataclass(frozen=True, slots=True)
class Publish:
    topic: str
    msg: msgspec.Raw  # the ``msg`` JSON as received, decoded by the topic's ROS type


@dataclass(frozen=True, slots=True)
class Status:
    level: str
    msg: str
    id: str | None


@dataclass(frozen=True, slots=True)
class OtherOp:
    op: str


Inbound = Publish | Status | OtherOp


class Frame(msgspec.Struct):
    """What a client reads of any inbound frame; ``msg`` stays raw JSON until the topic's
    type decodes it (a ``publish``), or is the text of a ``status``."""

    op: str
    topic: str | None = None
    msg: msgspec.Raw = msgspec.Raw()  # empty: no msg
    level: Any = ""
    id: Any = None


_decode_frame = decoder(Frame)
_decode_any = decoder(Any)


def decode_frame(text: str | bytes) -> Inbound:
    """Decode one inbound frame; raises DecodeError when malformed."""
    if len(text) > MAX_FRAME_BYTES:
        raise DecodeError(f"frame of {len(text)} bytes exceeds {MAX_FRAME_BYTES}")
    frame = _decode_frame(text)
    if frame.op == "publish":
        if not frame.topic:
            raise DecodeError("expected a topic name", ("topic",))
        if not frame.msg:
            raise DecodeError("missing field", ("msg",))
        return Publish(frame.topic, frame.msg)
    if frame.op == "status":
        msg = _decode_any(frame.msg) if frame.msg else ""
        ident = frame.id
        return Status(str(frame.level), str(msg), None if ident is None else str(ident))
    return OtherOp(frame.op)


def dumps(obj: dict[str, Any]) -> str:
    """Compact JSON text (msgspec); NaN and Infinity are refused (ValueError) rather
    than sent."""
    return encode(obj).decode()


def auth_frame(
    secret: str,
    client: str,
    dest: str,
    t: float,
    ttl: float = 60.0,
    level: str = "admin",
    rand: str | None = None,
) -> dict[str, Any]:
    """The rosauth ``auth`` op (rosbridge v2): a SHA-512 MAC over the shared secret.

    ``t`` and ``end`` go out as plain numbers of seconds: rosbridge builds
    ``rospy.Time(msg["t"])`` from them and refuses ``{secs, nsecs}`` objects.
    rosauth's MAC is over their whole seconds (``req.t.sec``).
    """
    rand = rand if rand is not None else secrets.token_hex(8)
    end = t + ttl
    return {
        "op": "auth",
        "mac": auth_mac(secret, client, dest, rand, t, level, end),
        "client": client,
        "dest": dest,
        "rand": rand,
        "t": t,
        "level": level,
        "end": end,
    }


def auth_mac(
    secret: str, client: str, dest: str, rand: str, t: float, level: str, end: float
) -> str:
    """rosauth's MAC: hex SHA-512 of secret + client + dest + rand + whole seconds of ``t``
    + level + whole seconds of ``end``."""
    text = f"{secret}{client}{dest}{rand}{math.floor(t)}{level}{math.floor(end)}"
    return hashlib.sha512(text.encode()).hexdigest()


@dataclass(slots=True)
class Subscription:
    topic: str
    type: str
    throttle_rate: int = 0
    queue_length: int = 0


@dataclass(slots=True)
class Session:
    """Client-side rosbridge state.

    Every method returns the frames (JSON text) to send *now*; a disconnected
    session returns none and remembers what must be sent on reconnect.
    """

    queue_limit: int = 1000
    secret: str | None = field(default=None, repr=False)  # never in a repr, log or traceback
    client_addr: str = "127.0.0.1"
    dest_addr: str = "127.0.0.1"
    connected: bool = False
    advertised: dict[str, str] = field(default_factory=dict)
    subscriptions: dict[str, Subscription] = field(default_factory=dict)
    dropped: int = 0
    _queue: deque[tuple[str, Any]] = field(default_factory=deque)
    _ids: itertools.count[int] = field(default_factory=lambda: itertools.count(1))

    def _id(self, op: str, topic: str) -> str:
        return f"{op}:{topic}:{next(self._ids)}"

    def _advertise_frame(self, topic: str, type_: str) -> str:
        return dumps(
            {"op": "advertise", "id": self._id("advertise", topic), "topic": topic, "type": type_}
        )

    def _subscribe_frame(self, sub: Subscription) -> str:
        frame: dict[str, Any] = {
            "op": "subscribe",
            "id": self._id("subscribe", sub.topic),
            "topic": sub.topic,
            "type": sub.type,
        }
        if sub.throttle_rate:
            frame["throttle_rate"] = sub.throttle_rate
        if sub.queue_length:
            frame["queue_length"] = sub.queue_length
        return dumps(frame)

    def _publish_frame(self, topic: str, msg: Any) -> str:
        return dumps(
            {"op": "publish", "id": self._id("publish", topic), "topic": topic, "msg": msg}
        )

    def advertise(self, topic: str, type_: str) -> list[str]:
        self.advertised[topic] = type_
        return [self._advertise_frame(topic, type_)] if self.connected else []

    def unadvertise(self, topic: str) -> list[str]:
        # Publishes queued for the topic go with it: sent after the reconnect
        # they would reach a topic that is no longer advertised.
        self._queue = deque(item for item in self._queue if item[0] != topic)
        if self.advertised.pop(topic, None) is None or not self.connected:
            return []
        return [dumps({"op": "unadvertise", "id": self._id("unadvertise", topic), "topic": topic})]

    def subscribe(
        self, topic: str, type_: str, throttle_rate: int = 0, queue_length: int = 0
    ) -> list[str]:
        sub = Subscription(topic, type_, throttle_rate, queue_length)
        self.subscriptions[topic] = sub
        return [self._subscribe_frame(sub)] if self.connected else []

    def unsubscribe(self, topic: str) -> list[str]:
        if self.subscriptions.pop(topic, None) is None or not self.connected:
            return []
        return [dumps({"op": "unsubscribe", "id": self._id("unsubscribe", topic), "topic": topic})]

    def publish(self, topic: str, msg: Any) -> list[str]:
        """Frame for a publish, or queue it (bounded) while disconnected.

        Raises ValueError for a topic never advertised and for a message that
        cannot be JSON (NaN, Infinity): those are programming errors.
        """
        if topic not in self.advertised:
            raise ValueError(f"publish on {topic!r}, which was never advertised")
        frame = self._publish_frame(topic, msg)  # validate now, not on reconnect
        if self.connected:
            return [frame]
        if len(self._queue) >= self.queue_limit:
            self._queue.popleft()
            self.dropped += 1
        self._queue.append((topic, msg))
        return []

    @property
    def queued(self) -> int:
        return len(self._queue)

    def on_connected(self, now: float) -> list[str]:
        """Frames to send on a fresh connection: auth, advertise, subscribe, then the queue."""
        self.connected = True
        frames: list[str] = []
        if self.secret:
            frames.append(dumps(auth_frame(self.secret, self.client_addr, self.dest_addr, now)))
        frames += [self._advertise_frame(t, ty) for t, ty in self.advertised.items()]
        frames += [self._subscribe_frame(s) for s in self.subscriptions.values()]
        while self._queue:
            frames.append(self._publish_frame(*self._queue.popleft()))
        return frames

    def on_disconnected(self) -> None:
        self.connected = False
