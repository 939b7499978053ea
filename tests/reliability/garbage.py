"""Seeded generators of bad input: valid frames and datagrams, mutated.

Fast and reproducible (``random.Random(seed)``): each item starts from a valid
rosbridge ``publish`` (every subscribed topic) or front-end datagram (every
event and command type) and is broken in one of many ways — a field deleted,
given the wrong type, NaN, Infinity, a huge integer, an engagement outside
[-1, 1], an unknown op or type, a bad ``seq``, truncated or flipped bytes,
invalid UTF-8, deep nesting, oversized. Some mutations leave the input valid;
:func:`classify_frame` and :func:`classify_datagram` say what a receiver should
make of each.
"""

from __future__ import annotations

import json
import random
from collections.abc import Iterator
from typing import Any

from rosmsgs import DECODERS

from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import MAX_DATAGRAM, decode_datagram, encode_datagram
from frog_bt.model import frontend as fm
from frog_bt.model.wire import CLOCK, INPUTS
from frog_bt.rosbridge.protocol import MAX_FRAME_BYTES, OtherOp, Publish, Status, decode_frame
from frog_bt.sim import msgs

T = 1_780_000_000.25
TOPIC_TYPES = {t.name: t.type for t in (*INPUTS.values(), CLOCK)}
VALID_MSGS: dict[str, dict[str, Any]] = {
    "geometry_msgs/PoseStamped": msgs.pose_stamped(97.19, 63.02, 0.898316, 0.43934, T),
    "std_msgs/Int32": {"data": 2},
    "std_msgs/String": {"data": "docked"},
    "diagnostic_msgs/DiagnosticArray": msgs.diagnostic_array(
        T,
        [
            {
                "level": 0,
                "name": "battery",
                "message": "ok",
                "hardware_id": "bms",
                "values": [("percentage", "73.5")],
            },
            {"level": 2, "name": "motors", "message": "hot", "hardware_id": "", "values": []},
        ],
    ),
    "frog_msgs/PersonDetections": msgs.person_detections(
        T,
        [
            {"id": 7, "position": (103.0, 36.0), "orientation": 181.0},
            {"id": 8, "position": (105.5, 35.0), "orientation": 90.0},
        ],
    ),
    "frog_msgs/FaceData": msgs.face_data(
        T,
        [
            {"id": 7, "engagement": 0.4, "distance": 1.2, "facing": True},
            {"id": 9, "engagement": -1.0, "distance": 3.5, "facing": False},
        ],
    ),
    "frog_msgs/TrackedPeople": msgs.tracked_people(
        T, [{"id": 3, "position": (103.0, 36.0)}, {"id": 4, "position": (1.0, 2.0)}]
    ),
    "rosgraph_msgs/Clock": msgs.clock(T),
}
VALID_FIELDS: dict[str, dict[str, Any]] = {
    "frontend_idle": {},
    "finish_introduction": {},
    "user_positive": {},
    "user_negative": {},
    "content_done": {"poi": "POI1", "part": "a"},
    "start_introduction": {"icl": True},
    "ask_tour": {"engaged": None},
    "start_poi": {"poi": "POI1", "waypoint": "POI1a", "part": "b"},
    "finish_poi": {"poi": "POI1"},
    "engagement": {"level": -0.25},
    "follow_me": {"on": False},
    "volume": {"percent": 80},
    "special_content": {"spot": "toilets"},
    "projector": {"on": True},
    "tour": {"state": "started", "reason": ""},
}
BAD_VALUES: list[Any] = [
    None,
    True,
    False,
    0,
    -1,
    1,
    2**31,
    -(2**31) - 1,
    2**64,
    10**400,
    1e308,
    1.5,
    -1.0000001,
    1.0000001,
    361.0,
    -0.5,
    float("nan"),
    float("inf"),
    float("-inf"),
    "",
    "x",
    "NaN",
    "1e400",
    "\u0000",
    "\udcff",
    "é" * 50,
    [],
    {},
    [1, 2],
    {"secs": 1},
    {"sec": 1, "nanosec": -1},
    {"secs": 1, "nsecs": 10**9},
    {"a": {"b": []}},
    [[[]]],
]
OPS = [
    None,
    5,
    "",
    "PUBLISH",
    "publish ",
    "fragment",
    "png",
    "auth",
    "set_level",
    "call_service",
    "service_response",
    "advertise",
    "subscribe",
    "status",
    "raw_bytes",
]
DEEP = "[" * 50_000
HUGE = '{"op":"publish","topic":"/FROG_pose","msg":"' + "x" * (MAX_FRAME_BYTES + 10) + '"}'
HUGE_DATAGRAM = b'{"type":"user_positive","seq":1,"pad":"' + b"x" * MAX_DATAGRAM + b'"}'


class Garbage:
    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)
        self._frames = [
            json.dumps({"op": "publish", "topic": topic, "msg": VALID_MSGS[type_]})
            for topic, type_ in TOPIC_TYPES.items()
        ]
        self._datagrams = [
            encode_datagram(type_, 1, fields) for type_, fields in VALID_FIELDS.items()
        ]

    # ------------------------------------------------------------ values

    def mutate(self, obj: Any) -> Any:
        """``obj`` (a fresh copy: it is changed in place) broken at one random point."""
        rng = self.rng
        if not isinstance(obj, dict | list) or not obj or rng.random() < 0.05:
            return rng.choice(BAD_VALUES)
        parent: Any = obj
        while True:
            key = (
                rng.choice(list(parent)) if isinstance(parent, dict) else rng.randrange(len(parent))
            )
            child = parent[key]
            if isinstance(child, dict | list) and child and rng.random() < 0.75:
                parent = child
                continue
            break
        action = rng.random()
        if action < 0.2:
            del parent[key]
        elif action < 0.3 and isinstance(parent, dict):
            parent[rng.choice(["extra", "", "msg", "op", "seq", "type"])] = rng.choice(BAD_VALUES)
        elif action < 0.4 and isinstance(parent, list):
            parent.append(rng.choice(BAD_VALUES))
        else:
            parent[key] = rng.choice(BAD_VALUES)
        return obj

    def _text(self, text: str) -> str | bytes:
        """Byte-level damage to serialised text."""
        rng = self.rng
        data = bytearray(text.encode())
        kind = rng.randrange(6)
        i = rng.randrange(len(data))
        if kind == 0:
            del data[i:]
        elif kind == 1:
            data[i] ^= 1 << rng.randrange(8)
        elif kind == 2:
            data.insert(i, rng.choice(b'{}[]",:\\\x00\xff\xc3 0eE-+.'))
        elif kind == 3:
            data[i:i] = data[: rng.randrange(len(data))]
        elif kind == 4:
            return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 40)))
        else:
            data[i:i] = rng.choice([b"NaN", b"Infinity", b"-Infinity", b"1e400", b"\xff\xfe"])
        return bytes(data) if rng.random() < 0.5 else data.decode("utf-8", "replace")

    # ------------------------------------------------------------ rosbridge

    def frame(self) -> str | bytes:
        """One rosbridge frame, mostly broken."""
        rng = self.rng
        valid = rng.choice(self._frames)
        roll = rng.random()
        if roll < 0.55:  # a publish on a subscribed topic, its msg broken
            frame = json.loads(valid)
            frame["msg"] = self.mutate(frame["msg"])
            return json.dumps(frame)  # NaN and Infinity come out as (non-JSON) tokens
        if roll < 0.75:
            return self._text(valid)
        if roll < 0.9:  # the envelope broken: op, topic, msg
            frame = json.loads(valid)
            what = rng.randrange(5)
            if what == 0:
                frame["op"] = rng.choice(OPS)
            elif what == 1:
                frame["topic"] = rng.choice([None, 7, "", "/not_subscribed", "/clockx", "x" * 300])
            elif what == 2:
                del frame[rng.choice(["op", "topic", "msg"])]
            elif what == 3:
                frame = {
                    "op": "status",
                    "level": rng.choice(BAD_VALUES[:8]),
                    "msg": rng.choice(["", "x", None]),
                    "id": rng.choice([None, 1, "a"]),
                }
            else:
                frame = rng.choice([[], [frame], 1, "publish", None, True])
            return json.dumps(frame)
        if roll < 0.999:
            return rng.choice(
                [
                    "",
                    " ",
                    "{",
                    "}",
                    "null",
                    "[]",
                    '{"op":}',
                    "{'op': 'publish'}",
                    DEEP[: rng.randrange(900, 3000)],
                ]
            )
        return rng.choice([HUGE, DEEP])

    def frames(self, n: int) -> Iterator[str | bytes]:
        for _ in range(n):
            yield self.frame()

    # ------------------------------------------------------------ front end

    def datagram(self) -> bytes:
        """One front-end datagram, mostly broken."""
        rng = self.rng
        valid = rng.choice(self._datagrams)
        roll = rng.random()
        if roll < 0.5:
            obj = json.loads(valid)
            obj["seq"] = rng.randrange(1, 50)
            return json.dumps(self.mutate(obj)).encode("utf-8", "surrogatepass")
        if roll < 0.7:
            out = self._text(valid.decode())
            return out if isinstance(out, bytes) else out.encode("utf-8", "surrogatepass")
        if roll < 0.95:
            obj = json.loads(valid)
            what = rng.randrange(4)
            if what == 0:
                obj["type"] = rng.choice(
                    [None, 1, "", "ACK", "hello", "frontend idle", "start_tour", "x" * 100]
                )
            elif what == 1:
                obj["seq"] = rng.choice([None, -1, 1.5, "1", True, [1], 2**70, float("nan")])
            elif what == 2:
                del obj[rng.choice(["type", "seq"])]
            else:
                obj = rng.choice([[], [obj], 1, "x", None])
            return json.dumps(obj).encode()
        if roll < 0.999:
            return rng.choice([b"", b" ", b"{", b"\xff\xfe", b"null", b"[]", DEEP[:2000].encode()])
        return HUGE_DATAGRAM

    def datagrams(self, n: int) -> Iterator[bytes]:
        for _ in range(n):
            yield self.datagram()


# ------------------------------------------------------------ what a receiver makes of it


def classify_frame(frame: str | bytes, subscribed: dict[str, str]) -> str:
    """``malformed`` (frame or msg), ``ignored`` (unknown op, unsubscribed topic),
    ``status`` or ``valid`` (a message the program would act on)."""
    try:
        event = decode_frame(frame)
    except DecodeError:
        return "malformed"
    if isinstance(event, Status):
        return "status"
    if isinstance(event, OtherOp):
        return "ignored"
    assert isinstance(event, Publish)
    type_ = subscribed.get(event.topic)
    if type_ is None:
        return "ignored"
    try:
        DECODERS[type_](event.msg)
    except DecodeError:
        return "malformed"
    return "valid"


def classify_datagram(data: bytes, inbound: dict[str, type[fm.FrontendMessage]]) -> str:
    """``malformed`` (not a datagram, or a message that does not decode), ``ack`` or ``valid``."""
    try:
        envelope = decode_datagram(data)
    except DecodeError:
        return "malformed"
    if envelope.type == "ack":
        return "ack"
    try:
        fm.decode_message(data, inbound)
    except DecodeError:
        return "malformed"
    return "valid"
