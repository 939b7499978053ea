"""The rosbridge server protocol, sans-I/O: frames in, actions out."""

from __future__ import annotations

import json
from typing import Any

import pytest

from frog_bt.rosbridge.protocol import auth_frame
from frog_bt.sim.rosbridge_protocol import BridgeServer, Close, Incoming, Send

NOW = 1_780_000_000.0


def frame(**fields: Any) -> str:
    return json.dumps(fields)


def sends(actions: list[Any]) -> list[tuple[int, dict[str, Any]]]:
    return [(a.client, json.loads(a.text)) for a in actions if isinstance(a, Send)]


@pytest.fixture
def server() -> BridgeServer:
    return BridgeServer(topic_types={"/FROG_pose": "geometry_msgs/PoseStamped"})


def test_publish_frames_go_to_subscribers_without_id(server: BridgeServer) -> None:
    a, b = server.connect(), server.connect()
    assert (
        server.receive(
            a,
            frame(op="subscribe", id="s1", topic="/FROG_pose", type="geometry_msgs/PoseStamped"),
            NOW,
        )
        == []
    )
    out = server.publish("/FROG_pose", {"x": 1}, NOW)
    assert sends(out) == [(a, {"op": "publish", "topic": "/FROG_pose", "msg": {"x": 1}})]
    assert server.publish("/other", {}, NOW) == []
    assert b not in [s.client for s in out]


def test_roslibpy_style_subscribe_with_compression(server: BridgeServer) -> None:
    c = server.connect()
    server.receive(
        c,
        frame(
            op="subscribe",
            id="subscribe:/FROG_pose:1",
            type="x",
            topic="/FROG_pose",
            compression="none",
            throttle_rate=0,
            queue_length=0,
        ),
        NOW,
    )
    assert len(server.publish("/FROG_pose", {}, NOW)) == 1


def test_unsubscribe_and_disconnect_stop_publishes(server: BridgeServer) -> None:
    a, b = server.connect(), server.connect()
    for c in (a, b):
        server.receive(c, frame(op="subscribe", topic="/t"), NOW)
    server.receive(a, frame(op="unsubscribe", id="u", topic="/t"), NOW)
    assert [s.client for s in server.publish("/t", {}, NOW)] == [b]
    server.disconnect(b)
    assert server.publish("/t", {}, NOW) == []


def test_throttle_rate(server: BridgeServer) -> None:
    c = server.connect()
    server.receive(c, frame(op="subscribe", topic="/t", throttle_rate=500), NOW)
    sent = [bool(server.publish("/t", {}, NOW + i * 0.1)) for i in range(11)]
    assert sent == [True, False, False, False, False, True, False, False, False, False, True]
    assert server.stats.throttled == 8


def test_client_publishes_reach_the_robot_and_other_subscribers(server: BridgeServer) -> None:
    exe, tool = server.connect(), server.connect()
    server.receive(tool, frame(op="subscribe", topic="/GotoWayPoint"), NOW)
    server.receive(
        exe,
        frame(op="advertise", id="a", topic="/GotoWayPoint", type="geometry_msgs/PoseStamped"),
        NOW,
    )
    out = server.receive(
        exe, frame(op="publish", id="p:1", topic="/GotoWayPoint", msg={"pose": 1}), NOW
    )
    assert out[-1] == Incoming(exe, "/GotoWayPoint", {"pose": 1})
    assert sends(out) == [(tool, {"op": "publish", "topic": "/GotoWayPoint", "msg": {"pose": 1}})]
    # publish without advertise works too (rosbridge advertises implicitly)
    assert server.receive(tool, frame(op="publish", topic="/x", msg={}), NOW) == [
        Incoming(tool, "/x", {})
    ]
    server.receive(exe, frame(op="unadvertise", topic="/GotoWayPoint"), NOW)
    assert server.stats.publishes_in == 2 and server.stats.malformed == 0


@pytest.mark.parametrize(
    "text",
    [
        "not json",
        "[1, 2]",
        '{"no": "op"}',
        '{"op": 5}',
        "NaN",
        frame(op="publish", msg={}),
        frame(op="publish", topic="/t"),
        frame(op="publish", topic="/t", msg=[1]),
        frame(op="subscribe", topic=""),
        frame(op="subscribe", topic="/t", throttle_rate="fast"),
        frame(op="advertise", topic="/t"),
        '{"op": "publish", "topic": "/t", "msg": {"x": NaN}}',
    ],
)
def test_malformed_frames_are_counted_and_answered_with_nothing(
    server: BridgeServer, text: str
) -> None:
    c = server.connect()
    assert server.receive(c, text, NOW) == []
    assert server.stats.malformed == 1


def test_status_only_when_the_client_asked_for_it(server: BridgeServer) -> None:
    c = server.connect()
    server.receive(c, frame(op="set_level", id="l", level="error"), NOW)
    ((_, status),) = sends(server.receive(c, "garbage", NOW))
    assert status["op"] == "status" and status["level"] == "error"


def test_unknown_ops_are_ignored(server: BridgeServer) -> None:
    c = server.connect()
    for op in ("fragment", "advertise_service", "status", "auth", "png"):
        assert server.receive(c, frame(op=op, id="x"), NOW) == []
    assert server.stats.malformed == 0 and server.stats.ignored == 4
    assert server.receive(99, frame(op="subscribe", topic="/t"), NOW) == []  # gone client


def test_rosapi_services(server: BridgeServer) -> None:
    c = server.connect()
    server.receive(c, frame(op="advertise", topic="/GotoWayPoint", type="geometry_msgs/Pose"), NOW)
    ((_, reply),) = sends(
        server.receive(c, frame(op="call_service", id="c1", service="/rosapi/get_time"), NOW)
    )
    assert reply == {
        "op": "service_response",
        "id": "c1",
        "service": "/rosapi/get_time",
        "values": {"time": {"secs": 1_780_000_000, "nsecs": 0}},
        "result": True,
    }
    ((_, reply),) = sends(
        server.receive(c, frame(op="call_service", service="/rosapi/topics"), NOW)
    )
    assert set(reply["values"]["topics"]) == {"/FROG_pose", "/GotoWayPoint"}
    ((_, reply),) = sends(
        server.receive(
            c,
            frame(op="call_service", service="/rosapi/topic_type", args={"topic": "/FROG_pose"}),
            NOW,
        )
    )
    assert reply["values"] == {"type": "geometry_msgs/PoseStamped"}
    ((_, reply),) = sends(server.receive(c, frame(op="call_service", service="/x/y"), NOW))
    assert reply["result"] is False


def test_auth_with_a_secret() -> None:
    server = BridgeServer(secret="s3cret", auth_time=lambda: NOW)
    good = server.connect()
    assert (
        server.receive(
            good, json.dumps(auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW + 0.7)), NOW
        )
        == []
    )
    server.receive(good, frame(op="subscribe", topic="/t"), NOW)
    assert len(server.publish("/t", {}, NOW)) == 1

    wrong = server.connect()
    server.receive(wrong, frame(op="subscribe", topic="/t"), NOW)  # before auth: dropped
    assert server.publish("/t", {}, NOW)[0].client == good
    assert wrong not in server.clients

    bad_mac = server.connect()
    out = server.receive(bad_mac, json.dumps(auth_frame("guess", "a", "b", NOW)), NOW)
    assert out == [Close(bad_mac, "authentication failed")]
    assert server.stats.auth_failures == 2


def _authenticated_server() -> BridgeServer:
    return BridgeServer(secret="s3cret", auth_time=lambda: NOW)


def test_auth_in_the_number_form_is_accepted() -> None:
    server = _authenticated_server()
    c = server.connect()
    auth = auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW + 0.25)
    assert isinstance(auth["t"], float)
    assert server.receive(c, json.dumps(auth), NOW) == []
    assert server.clients[c].authenticated


def test_auth_in_the_object_form_is_not_understood_and_the_next_frame_closes() -> None:
    # rosbridge 0.11.17: rospy.Time({...}) raises, "Unknown operation: auth" is logged,
    # nothing is sent; the next frame of the unauthenticated client closes it.
    server = _authenticated_server()
    c = server.connect()
    auth = auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW)
    auth["t"], auth["end"] = {"secs": int(NOW), "nsecs": 0}, {"secs": int(NOW) + 60, "nsecs": 0}
    assert server.receive(c, json.dumps(auth), NOW) == []
    assert not server.clients[c].authenticated
    assert server.receive(c, frame(op="subscribe", topic="/t", type="std_msgs/String"), NOW) == [
        Close(c, "authentication failed")
    ]


@pytest.mark.parametrize(
    ("what", "auth"),
    [
        ("wrong secret", auth_frame("guess", "10.0.0.2", "10.0.0.1", NOW)),
        ("t 5 s behind", auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW - 5.0)),
        ("t 6 s ahead", auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW + 6.0)),
        ("end already past", auth_frame("s3cret", "10.0.0.2", "10.0.0.1", NOW - 2.0, ttl=1.0)),
        ("a bool for t", {**auth_frame("s3cret", "a", "b", NOW), "t": True}),
    ],
)
def test_a_bad_auth_closes_the_connection_without_a_status_frame(what: str, auth: Any) -> None:
    server = _authenticated_server()
    c = server.connect()
    out = server.receive(c, json.dumps(auth), NOW)
    if what == "a bool for t":  # not a number: not understood, closed by the next frame
        assert out == []
        out = server.receive(c, frame(op="advertise", topic="/t", type="std_msgs/String"), NOW)
    assert out == [Close(c, "authentication failed")], what
    assert c not in server.clients


def test_auth_without_a_secret_is_accepted_and_ignored(server: BridgeServer) -> None:
    c = server.connect()
    assert server.receive(c, json.dumps(auth_frame("any", "a", "b", NOW)), NOW) == []
    assert server.clients[c].authenticated and server.stats.malformed == 0
