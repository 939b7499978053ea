"""The sans-I/O rosbridge Session and frame codec, fed and read as strings."""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frog_bt.errors import DecodeError
from frog_bt.model.ros import ROS_TYPES
from frog_bt.rosbridge.protocol import (
    MAX_FRAME_BYTES,
    OtherOp,
    Publish,
    Session,
    Status,
    auth_frame,
    decode_frame,
    dumps,
)


def parse(frames: list[str]) -> list[dict[str, Any]]:
    return [json.loads(f) for f in frames]


def connected(**kwargs: Any) -> Session:
    session = Session(**kwargs)
    assert session.on_connected(0.0) == []  # nothing to restore yet
    return session


# ---------------------------------------------------------------- outbound frames


def test_advertise_and_subscribe_frames_carry_ids() -> None:
    s = connected()
    [adv] = parse(s.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped"))
    [sub] = parse(s.subscribe("/FROG_response", "std_msgs/Int32"))
    assert adv == {
        "op": "advertise",
        "id": adv["id"],
        "topic": "/GotoWayPoint",
        "type": "geometry_msgs/PoseStamped",
    }
    assert sub == {
        "op": "subscribe",
        "id": sub["id"],
        "topic": "/FROG_response",
        "type": "std_msgs/Int32",
    }
    assert isinstance(adv["id"], str) and isinstance(sub["id"], str)
    assert adv["id"] != sub["id"]


def test_throttle_rate_and_queue_length_only_when_set() -> None:
    s = connected()
    [plain] = parse(s.subscribe("/a", "std_msgs/Int32"))
    [throttled] = parse(s.subscribe("/b", "std_msgs/Int32", throttle_rate=100))
    [queued] = parse(s.subscribe("/c", "std_msgs/Int32", queue_length=5))
    assert "throttle_rate" not in plain and "queue_length" not in plain
    assert throttled["throttle_rate"] == 100 and "queue_length" not in throttled
    assert queued["queue_length"] == 5 and "throttle_rate" not in queued


def test_unsubscribe_and_unadvertise() -> None:
    s = connected()
    s.advertise("/a", "std_msgs/String")
    s.subscribe("/b", "std_msgs/Int32")
    [unadv] = parse(s.unadvertise("/a"))
    [unsub] = parse(s.unsubscribe("/b"))
    assert unadv["op"] == "unadvertise" and unadv["topic"] == "/a" and "id" in unadv
    assert unsub["op"] == "unsubscribe" and unsub["topic"] == "/b" and "id" in unsub
    # a second time there is nothing to undo
    assert s.unadvertise("/a") == [] and s.unsubscribe("/b") == []
    assert s.on_connected(0.0) == []


def test_publish_while_connected_is_sent_with_unique_ids() -> None:
    s = connected()
    s.advertise("/a", "std_msgs/Int32")
    frames = parse(s.publish("/a", {"data": 1}) + s.publish("/a", {"data": 2}))
    assert [f["msg"] for f in frames] == [{"data": 1}, {"data": 2}]
    assert all(f["op"] == "publish" and f["topic"] == "/a" for f in frames)
    assert len({f["id"] for f in frames}) == 2


def test_publish_on_unadvertised_topic_is_refused() -> None:
    with pytest.raises(ValueError, match="never advertised"):
        connected().publish("/nowhere", {"data": 1})


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_and_infinity_are_refused_on_send(bad: float) -> None:
    for s in (connected(), Session()):  # connected, and queueing while down
        s.advertise("/a", "geometry_msgs/PoseStamped")
        with pytest.raises(ValueError):
            s.publish("/a", {"pose": {"position": {"x": bad}}})
        assert s.queued == 0
    with pytest.raises(ValueError):
        dumps({"x": [1.0, bad]})


def test_publish_while_disconnected_is_queued_not_sent() -> None:
    s = Session()
    s.advertise("/a", "std_msgs/Int32")
    assert s.publish("/a", {"data": 1}) == []
    assert s.queued == 1 and s.dropped == 0


def test_bounded_queue_drops_oldest_and_counts() -> None:
    s = Session(queue_limit=3)
    s.advertise("/a", "std_msgs/Int32")
    for i in range(5):
        s.publish("/a", {"data": i})
    assert s.queued == 3 and s.dropped == 2
    frames = parse(s.on_connected(0.0))
    assert [f["msg"]["data"] for f in frames if f["op"] == "publish"] == [2, 3, 4]


def test_on_connected_restores_everything_in_order() -> None:
    s = Session()
    s.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped")
    s.advertise("/docking/dock", "std_msgs/String")
    s.subscribe("/FROG_response", "std_msgs/Int32", throttle_rate=50)
    s.publish("/docking/dock", {"data": "undock"})
    s.publish("/GotoWayPoint", {"pose": 1})
    frames = parse(s.on_connected(0.0))
    assert [(f["op"], f["topic"]) for f in frames] == [
        ("advertise", "/GotoWayPoint"),
        ("advertise", "/docking/dock"),
        ("subscribe", "/FROG_response"),
        ("publish", "/docking/dock"),
        ("publish", "/GotoWayPoint"),
    ]
    assert frames[2]["throttle_rate"] == 50
    assert s.queued == 0 and s.connected

    # after a drop, the same advertise/subscribe go again, with fresh ids
    s.on_disconnected()
    again = parse(s.on_connected(1.0))
    assert [(f["op"], f["topic"]) for f in again] == [(f["op"], f["topic"]) for f in frames[:3]]
    assert not {f["id"] for f in again} & {f["id"] for f in frames}


def test_unadvertise_while_down_drops_its_queued_publishes() -> None:
    s = Session()
    s.advertise("/a", "std_msgs/Int32")
    s.advertise("/b", "std_msgs/Int32")
    s.publish("/a", {"data": 1})
    s.publish("/b", {"data": 2})
    assert s.unadvertise("/a") == []
    frames = parse(s.on_connected(0.0))
    assert [(f["op"], f["topic"]) for f in frames] == [("advertise", "/b"), ("publish", "/b")]


def test_unsubscribe_while_down_is_not_restored() -> None:
    s = Session()
    s.subscribe("/a", "std_msgs/Int32")
    s.subscribe("/b", "std_msgs/Int32")
    assert s.unsubscribe("/a") == []
    assert [f["topic"] for f in parse(s.on_connected(0.0))] == ["/b"]


# ---------------------------------------------------------------- auth


def _mac(secret: str, f: dict[str, Any]) -> str:
    # rosauth: secret + client + dest + rand + t.sec + level + end.sec (whole seconds)
    text = f"{secret}{f['client']}{f['dest']}{f['rand']}{int(f['t'])}{f['level']}{int(f['end'])}"
    return hashlib.sha512(text.encode()).hexdigest()


def test_auth_frame_first_only_with_a_secret_and_mac_verifies() -> None:
    plain = Session()
    plain.advertise("/a", "std_msgs/Int32")
    assert [f["op"] for f in parse(plain.on_connected(100.0))] == ["advertise"]

    s = Session(secret="s3cret", client_addr="10.0.0.2", dest_addr="10.0.0.1")
    s.advertise("/a", "std_msgs/Int32")
    auth, adv = parse(s.on_connected(1_700_000_000.25))
    assert adv["op"] == "advertise"
    assert auth["op"] == "auth"
    assert auth["client"] == "10.0.0.2" and auth["dest"] == "10.0.0.1"
    # numbers of seconds, as rosbridge's rospy.Time(msg["t"]) needs (not {secs, nsecs})
    assert auth["t"] == 1_700_000_000.25 and type(auth["end"]) is float
    assert auth["end"] == 1_700_000_060.25
    assert auth["mac"] == _mac("s3cret", auth)
    assert auth["mac"] != _mac("wrong", auth)


def test_auth_rand_is_fresh_each_time() -> None:
    a = auth_frame("k", "c", "d", 10.0)
    b = auth_frame("k", "c", "d", 10.0)
    assert a["rand"] != b["rand"]
    fixed = auth_frame("k", "c", "d", 10.0, rand="abc")
    assert fixed["mac"] == _mac("k", fixed)


# ---------------------------------------------------------------- inbound frames


def test_publish_frame() -> None:
    frame = '{"op":"publish","topic":"/FROG_response","msg":{"data":2}}'
    for text in (frame, frame.encode()):
        event = decode_frame(text)
        assert isinstance(event, Publish) and event.topic == "/FROG_response"
        assert msgspec.json.decode(event.msg) == {"data": 2}  # the msg stays raw JSON


def test_status_frame() -> None:
    assert decode_frame(
        '{"op":"status","level":"error","msg":"no such topic","id":"x:1"}'
    ) == Status("error", "no such topic", "x:1")
    assert decode_frame('{"op":"status"}') == Status("", "", None)


@pytest.mark.parametrize("op", ["set_level", "service_response", "png", "fragment", ""])
def test_unknown_ops_are_other(op: str) -> None:
    assert decode_frame(json.dumps({"op": op, "whatever": [1, 2]})) == OtherOp(op)


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("", "not JSON"),
        ("{", "not JSON"),
        ("[1, 2]", "expected `object`"),
        ('"publish"', "expected `object`"),
        ("{}", "op"),
        ('{"op": 3}', "op"),
        ('{"op":"publish","msg":{}}', "topic"),
        ('{"op":"publish","topic":"","msg":{}}', "topic"),
        ('{"op":"publish","topic":7,"msg":{}}', "topic"),
        ('{"op":"publish","topic":"/a"}', "msg"),
        ('{"op":"publish","topic":"/a","msg":{"data":NaN}}', "not JSON"),
        ('{"op":"publish","topic":"/a","msg":{"data":-Infinity}}', "not JSON"),
        (b"\xff\xfe\xfa", "not JSON"),
        ("[" * 100_000, "expected `object`"),
    ],
)
def test_malformed_frames_raise_decode_error(text: str | bytes, where: str) -> None:
    with pytest.raises(DecodeError, match=where):
        decode_frame(text)


def test_a_huge_number_is_left_to_the_type_to_refuse() -> None:
    event = decode_frame('{"op":"publish","topic":"/a","msg":{"data":' + "9" * 5000 + "}}")
    assert isinstance(event, Publish)
    with pytest.raises(DecodeError, match="data"):
        ROS_TYPES["std_msgs/Int32"].decode(event.msg)


def test_oversized_frame_is_refused() -> None:
    big = '{"op":"publish","topic":"/a","msg":"' + "x" * MAX_FRAME_BYTES + '"}'
    with pytest.raises(DecodeError, match="exceeds"):
        decode_frame(big)


# ---------------------------------------------------------------- properties

json_scalars = (
    st.none()
    | st.booleans()
    | st.integers(-(2**70), 2**70)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=20)
)
finite_json = st.recursive(
    json_scalars,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=20,
)
frame_keys = st.sampled_from(["op", "topic", "msg", "level", "id", "type"])
frame_like = st.dictionaries(
    frame_keys | st.text(max_size=5),
    st.sampled_from(["publish", "status", "advertise", "/a", ""]) | finite_json,
    max_size=5,
)


def _check_decode(value: str | bytes) -> None:
    try:
        result = decode_frame(value)
    except DecodeError:
        return
    assert isinstance(result, Publish | Status | OtherOp)


@given(st.text() | st.binary())
def test_decode_frame_on_arbitrary_text_or_bytes(value: str | bytes) -> None:
    _check_decode(value)


@given(finite_json | frame_like)
def test_decode_frame_on_arbitrary_json(value: Any) -> None:
    _check_decode(json.dumps(value))
    _check_decode(json.dumps(value).encode("utf-8"))


@given(st.text(min_size=1, max_size=30), finite_json)
@settings(max_examples=200)
def test_publish_frames_round_trip(topic: str, msg: Any) -> None:
    s = connected()
    s.advertise(topic, "std_msgs/String")
    [frame] = s.publish(topic, msg)
    event = decode_frame(frame)
    assert isinstance(event, Publish) and event.topic == topic
    assert msgspec.json.decode(event.msg) == msg


@given(st.lists(st.integers(0, 100), max_size=30), st.integers(1, 10))
def test_queue_keeps_the_newest_in_order(values: list[int], limit: int) -> None:
    s = Session(queue_limit=limit)
    s.advertise("/a", "std_msgs/Int32")
    for v in values:
        s.publish("/a", {"data": v})
    assert s.dropped == max(0, len(values) - limit)
    sent = [json.loads(f)["msg"]["data"] for f in s.on_connected(0.0)[1:]]
    assert sent == values[-limit:]
