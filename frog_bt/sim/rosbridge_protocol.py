"""rosbridge v2 *server* protocol, sans-I/O: text in, actions out.

:class:`BridgeServer` keeps each client's advertisements and subscriptions
and turns what a client sends into :class:`Send` (a frame for one client),
:class:`Incoming` (a publish the robot model should see) and :class:`Close`
(drop the client) actions. No sockets and no clock: ``now`` is passed in
(seconds, simulated time) and used for ``throttle_rate``.

It behaves like rosbridge_suite's server where the executive and roslibpy can
tell: ``publish`` frames carry no ``id``; no ``status`` frame is sent unless the
client asked for them with ``set_level``; ``publish`` works with or without
``advertise``; a publish is also forwarded to every client subscribed to the
topic; unknown ops are ignored; malformed frames are logged and counted.

With a shared secret it checks ``auth`` as rosbridge 0.11.17 with rosauth does
(``real-rosbridge/README.md``): until a client has authenticated, any frame but
``auth`` closes it; an ``auth`` whose ``t`` or ``end`` is not a number (the
``{secs, nsecs}`` object form) is not understood ("Unknown operation: auth" in
the real server's log) and leaves the client unauthenticated, so its next frame
closes it; an ``auth`` with a wrong MAC, a ``t`` whole seconds off the server's
time by ``allowed_time_delta`` (5 s) or more, or an ``end`` already past closes
it at once. A close never comes with a status frame. rosauth compares with ROS
time, which is the wall clock on a robot without sim time: ``auth_time``
(injected, default ``time.time``). ``call_service`` answers ``/rosapi/get_time``,
``/rosapi/topics`` and ``/rosapi/topic_type``; other services fail.
"""

from __future__ import annotations

import hmac
import itertools
import json
import logging
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import msgspec

from frog_bt.errors import DecodeError
from frog_bt.model.ros import encode_time
from frog_bt.rosbridge.protocol import MAX_FRAME_BYTES, auth_mac, dumps

log = logging.getLogger(__name__)

STATUS_LEVELS = ("none", "error", "warning", "info")


@dataclass(frozen=True, slots=True)
class Send:
    client: int
    text: str


@dataclass(frozen=True, slots=True)
class Incoming:
    client: int
    topic: str
    msg: dict[str, Any]


@dataclass(frozen=True, slots=True)
class Close:
    client: int
    reason: str


Action = Send | Incoming | Close


@dataclass(slots=True)
class ClientSubscription:
    topic: str
    type: str
    throttle_rate: int = 0  # ms between messages, 0: every message
    queue_length: int = 0
    last_sent: float | None = None


@dataclass(slots=True)
class Client:
    id: int
    authenticated: bool = False
    status_level: str = "none"
    advertised: dict[str, str] = field(default_factory=dict)
    subscriptions: dict[str, ClientSubscription] = field(default_factory=dict)


@dataclass(slots=True)
class ServerStats:
    frames: int = 0
    malformed: int = 0
    ignored: int = 0  # unknown ops
    publishes_in: int = 0
    publishes_out: int = 0  # frames, one per subscriber
    throttled: int = 0
    auth_failures: int = 0


def publish_frame(topic: str, msg: Any) -> str:
    """A server ``publish`` frame (no ``id``, as rosbridge sends them)."""
    return dumps({"op": "publish", "topic": topic, "msg": msg})


class BridgeServer:
    """All clients of one rosbridge server; ``topic_types`` are the server's own topics."""

    def __init__(
        self,
        secret: str | None = None,
        topic_types: Mapping[str, str] | None = None,
        *,
        auth_time: Callable[[], float] = time.time,
        allowed_time_delta: float = 5.0,
    ) -> None:
        self.secret = secret
        self.auth_time = auth_time
        self.allowed_time_delta = allowed_time_delta
        self.topic_types = dict(topic_types or {})
        self.clients: dict[int, Client] = {}
        self.stats = ServerStats()
        self._ids = itertools.count(1)

    # ------------------------------------------------------------ connections

    def connect(self) -> int:
        """Register a new client; its id."""
        client = Client(next(self._ids), authenticated=self.secret is None)
        self.clients[client.id] = client
        return client.id

    def disconnect(self, client: int) -> None:
        self.clients.pop(client, None)

    # ------------------------------------------------------------ inbound

    def receive(self, client: int, text: str | bytes, now: float) -> list[Action]:
        """Act on one frame from ``client``."""
        state = self.clients.get(client)
        if state is None:
            return []
        self.stats.frames += 1
        try:
            frame = _decode(text)
        except DecodeError as exc:
            return self._malformed(state, str(exc))
        op = frame["op"]
        if not state.authenticated:
            return self._authenticate(state, frame)
        handler = _HANDLERS.get(op)
        if handler is None:
            if op != "auth":
                self.stats.ignored += 1
                log.debug("client %d: op %r ignored", client, op)
            return []
        try:
            return handler(self, state, frame, now)
        except DecodeError as exc:
            return self._malformed(state, f"{op}: {exc}")

    def _malformed(self, state: Client, reason: str) -> list[Action]:
        self.stats.malformed += 1
        log.warning("client %d: malformed frame: %s", state.id, reason)
        if STATUS_LEVELS.index(state.status_level) >= STATUS_LEVELS.index("error"):
            return [Send(state.id, dumps({"op": "status", "level": "error", "msg": reason}))]
        return []

    def _authenticate(self, state: Client, frame: dict[str, Any]) -> list[Action]:
        assert self.secret is not None
        if frame["op"] == "auth":
            t, end = frame.get("t"), frame.get("end")
            if not (_is_number(t) and _is_number(end)):
                # rospy.Time(msg["t"]) raises: the real server logs "Unknown operation:
                # auth" and waits for the next frame, which then closes the connection.
                self.stats.auth_failures += 1
                log.warning(
                    "client %d: auth with t/end not numbers of seconds: Unknown operation: auth",
                    state.id,
                )
                return []
            if self._auth_ok(frame, float(t), float(end)):  # type: ignore[arg-type]
                state.authenticated = True
                log.info("client %d authenticated", state.id)
                return []
        self.stats.auth_failures += 1
        log.warning("client %d did not authenticate (%s); closing", state.id, frame["op"])
        self.clients.pop(state.id, None)
        return [Close(state.id, "authentication failed")]

    def _auth_ok(self, frame: dict[str, Any], t: float, end: float) -> bool:
        """rosauth's check: the time within the allowed delta (whole seconds), ``end`` still
        ahead, and the MAC."""
        assert self.secret is not None
        now = self.auth_time()
        if not (math.floor(abs(t - now)) < self.allowed_time_delta and end > now):
            return False
        try:
            client, dest, rand, level = (str(frame[k]) for k in ("client", "dest", "rand", "level"))
            mac = str(frame["mac"])
        except KeyError:
            return False
        expected = auth_mac(self.secret, client, dest, rand, t, level, end)
        return hmac.compare_digest(mac, expected)

    def _advertise(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        state.advertised[_topic(frame)] = _text(frame, "type")
        return []

    def _unadvertise(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        state.advertised.pop(_topic(frame), None)
        return []

    def _publish(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        topic = _topic(frame)
        msg = frame.get("msg")
        if not isinstance(msg, dict):
            raise DecodeError("expected an object", ("msg",))
        self.stats.publishes_in += 1
        # forwarded first: the robot's answer comes after the message it answers
        return [*self.publish(topic, msg, now), Incoming(state.id, topic, msg)]

    def _subscribe(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        topic = _topic(frame)
        type_ = frame.get("type") or self.topic_types.get(topic, "")
        throttle, queue = _count(frame, "throttle_rate"), _count(frame, "queue_length")
        state.subscriptions[topic] = ClientSubscription(topic, str(type_), throttle, queue)
        return []

    def _unsubscribe(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        state.subscriptions.pop(_topic(frame), None)
        return []

    def _set_level(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        level = frame.get("level")
        if level in STATUS_LEVELS:
            state.status_level = level
        return []

    def _call_service(self, state: Client, frame: dict[str, Any], now: float) -> list[Action]:
        service = _text(frame, "service")
        given = frame.get("args")
        args: dict[str, Any] = given if isinstance(given, dict) else {}
        values: Any
        result = True
        if service == "/rosapi/get_time":
            values = {"time": msgspec.to_builtins(encode_time(now))}
        elif service == "/rosapi/topics":
            types = self._all_topic_types()
            values = {"topics": list(types), "types": list(types.values())}
        elif service == "/rosapi/topic_type":
            values = {"type": self._all_topic_types().get(str(args.get("topic", "")), "")}
        else:
            values, result = f"service {service} is not available in the simulator", False
        reply: dict[str, Any] = {
            "op": "service_response",
            "service": service,
            "values": values,
            "result": result,
        }
        if "id" in frame:
            reply["id"] = frame["id"]
        return [Send(state.id, dumps(reply))]

    def _all_topic_types(self) -> dict[str, str]:
        types = dict(self.topic_types)
        for client in self.clients.values():
            for topic, type_ in client.advertised.items():
                types.setdefault(topic, type_)
        return types

    # ------------------------------------------------------------ outbound

    def publish(self, topic: str, msg: Any, now: float) -> list[Send]:
        """Frames of one publish for every client subscribed to ``topic`` (throttled)."""
        text: str | None = None
        out: list[Send] = []
        for client in self.clients.values():
            sub = client.subscriptions.get(topic)
            if sub is None or not client.authenticated:
                continue
            if (
                sub.throttle_rate
                and sub.last_sent is not None
                and now - sub.last_sent < sub.throttle_rate / 1000.0 - 1e-6
            ):
                self.stats.throttled += 1
                continue
            sub.last_sent = now
            if text is None:
                text = publish_frame(topic, msg)
            out.append(Send(client.id, text))
        self.stats.publishes_out += len(out)
        return out

    def subscribers(self, topic: str) -> list[int]:
        return [c.id for c in self.clients.values() if topic in c.subscriptions]


_HANDLERS = {
    "advertise": BridgeServer._advertise,
    "unadvertise": BridgeServer._unadvertise,
    "publish": BridgeServer._publish,
    "subscribe": BridgeServer._subscribe,
    "unsubscribe": BridgeServer._unsubscribe,
    "set_level": BridgeServer._set_level,
    "call_service": BridgeServer._call_service,
}


def _decode(text: str | bytes) -> dict[str, Any]:
    if len(text) > MAX_FRAME_BYTES:
        raise DecodeError(f"frame of {len(text)} bytes exceeds {MAX_FRAME_BYTES}")
    try:
        frame = json.loads(text, parse_constant=_reject_constant)
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise DecodeError(f"not JSON: {exc}"[:200]) from None
    if not isinstance(frame, dict):
        raise DecodeError(f"expected a JSON object, got {type(frame).__name__}")
    if not isinstance(frame.get("op"), str):
        raise DecodeError("expected a string", ("op",))
    return frame


def _reject_constant(name: str) -> Any:
    raise ValueError(f"{name} is not valid JSON")


def _topic(frame: dict[str, Any]) -> str:
    topic = frame.get("topic")
    if not isinstance(topic, str) or not topic:
        raise DecodeError("expected a topic name", ("topic",))
    return topic


def _text(frame: dict[str, Any], key: str) -> str:
    value = frame.get(key)
    if not isinstance(value, str) or not value:
        raise DecodeError("expected a non-empty string", (key,))
    return value


def _count(frame: dict[str, Any], key: str) -> int:
    value = frame.get(key, 0)
    if value is None:
        return 0
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value < 0
    ):
        raise DecodeError(f"expected a number >= 0, got {value!r}"[:200], (key,))
    return int(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
