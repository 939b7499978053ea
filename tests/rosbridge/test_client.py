"""RosbridgeClient against a minimal in-test rosbridge server on 127.0.0.1.

Every wait is on an event or a queue (the server's received frames, the
client's callbacks), never a sleep; backoffs are tiny so reconnects are fast.
"""

from __future__ import annotations

import asyncio
import hashlib
import itertools
import json
import logging
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import Any

import pytest
from rosmsgs import encode_int32, encode_pose, encode_string
from websockets.asyncio.server import serve

from frog_bt.model.ros import Pose
from frog_bt.rosbridge.client import (
    FRAME_TOPIC,
    LinkState,
    RosbridgeClient,
    backoff_delays,
)
from frog_bt.warning_limit import WarningLimiter

from .conftest import FakeRosbridge, free_port, run

FAST = {"backoff_initial": 0.01, "backoff_max": 0.05}


class Recorder:
    """Collects the client's callbacks into queues tests can await."""

    def __init__(self) -> None:
        self.messages: asyncio.Queue[tuple[str, Any]] = asyncio.Queue()
        self.links: asyncio.Queue[LinkState] = asyncio.Queue()
        self.link_log: list[LinkState] = []

    def on_message(self, topic: str, value: Any) -> None:
        self.messages.put_nowait((topic, value))

    def on_link(self, state: LinkState) -> None:
        self.link_log.append(state)
        self.links.put_nowait(state)

    async def link(self, connected: bool) -> LinkState:
        state = await self.links.get()
        assert state.connected is connected, state
        return state


@asynccontextmanager
async def client_for(url: str, rec: Recorder, **kwargs: Any) -> AsyncIterator[RosbridgeClient]:
    client = RosbridgeClient(
        url, on_message=rec.on_message, on_link=rec.on_link, **{**FAST, **kwargs}
    )
    try:
        yield client
    finally:
        await client.close()


def ops(frames: list[dict[str, Any]]) -> list[tuple[str, str]]:
    return [(f["op"], f.get("topic", "")) for f in frames]


# ---------------------------------------------------------------- happy path


def test_subscribe_then_receive_typed_values() -> None:
    async def main() -> None:
        rec = Recorder()
        async with FakeRosbridge() as server, client_for(server.url, rec) as client:
            client.subscribe("/FROG_response", "std_msgs/Int32")
            client.subscribe("/FROG_pose", "geometry_msgs/PoseStamped", throttle_rate=100)
            client.start()
            sub1, sub2 = await server.take(2)
            assert sub1 == {
                "op": "subscribe",
                "id": sub1["id"],
                "topic": "/FROG_response",
                "type": "std_msgs/Int32",
            }
            assert sub2["type"] == "geometry_msgs/PoseStamped" and sub2["throttle_rate"] == 100
            assert sub1["id"] != sub2["id"]

            await server.publish("/not_subscribed", {"data": 1})  # ignored, not malformed
            await server.publish("/FROG_response", {"data": 2})
            await server.publish(
                "/FROG_pose",
                {
                    "header": {"stamp": {"sec": 10, "nanosec": 0}, "frame_id": "map"},
                    "pose": {
                        "position": {"x": 1.5, "y": 2.5, "z": 0},
                        "orientation": {"x": 0, "y": 0, "z": 0, "w": 1},
                    },
                },
            )
            assert await rec.messages.get() == ("/FROG_response", 2)
            assert await rec.messages.get() == ("/FROG_pose", Pose(10.0, "map", 1.5, 2.5, 0.0, 1.0))
            assert client.stats.received == 3 and client.stats.malformed == 0

            client.unsubscribe("/FROG_pose")
            unsub = await server.next_frame()
            assert ops([unsub]) == [("unsubscribe", "/FROG_pose")] and "id" in unsub

    run(main())


def test_publish_reaches_server_with_ids_in_order() -> None:
    async def main() -> None:
        rec = Recorder()
        async with FakeRosbridge() as server, client_for(server.url, rec) as client:
            client.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped")
            client.advertise("/docking/dock", "std_msgs/String")
            client.start()
            assert await client.wait_connected(5)
            assert ops(await server.take(2)) == [
                ("advertise", "/GotoWayPoint"),
                ("advertise", "/docking/dock"),
            ]
            goal = encode_pose(97.19, 63.02, 0.898316, 0.43934, stamp=100.0)
            client.publish("/docking/dock", encode_string("undock"))
            client.publish("/GotoWayPoint", goal)
            client.publish("/docking/dock", encode_string("dock"))
            frames = await server.take(3)
            assert ops(frames) == [
                ("publish", "/docking/dock"),
                ("publish", "/GotoWayPoint"),
                ("publish", "/docking/dock"),
            ]
            assert [f["msg"] for f in frames] == [{"data": "undock"}, goal, {"data": "dock"}]
            assert len({f["id"] for f in frames}) == 3

            with pytest.raises(ValueError, match="never advertised"):
                client.publish("/ApproachPeopleFar", encode_int32(3))
            with pytest.raises(ValueError):
                client.publish("/GotoWayPoint", encode_pose(float("nan"), 0, 0, 1, 0))

            client.unadvertise("/docking/dock")
            assert ops([await server.next_frame()]) == [("unadvertise", "/docking/dock")]
            assert client.stats.sent == 6

    run(main())


def test_a_command_leaves_when_it_is_sent() -> None:
    """A publish is written to the transport before the call returns (a command a tick
    sends leaves while the tick goes on, not after it and what the loop has queued);
    with the transport's buffer busy (a slow link) it waits for the writer task, and
    what comes after it waits behind it, in order."""

    async def main() -> None:
        rec = Recorder()
        async with FakeRosbridge() as server, client_for(server.url, rec) as client:
            client.advertise("/docking/dock", "std_msgs/String")
            client.start()
            assert await client.wait_connected(5)
            await server.take(1)
            await client.flush(5)
            sent = client.stats.sent
            client.publish("/docking/dock", encode_string("undock"))  # no await since
            assert client.stats.sent == sent + 1 and not client._outbox
            ws = client._ws
            assert ws is not None
            real = ws.transport.get_write_buffer_size  # a busy buffer, as on a slow link
            ws.transport.get_write_buffer_size = lambda: 1  # type: ignore[method-assign]
            client.publish("/docking/dock", encode_string("dock"))
            client.publish("/docking/dock", encode_string("undock"))
            assert len(client._outbox) == 2
            ws.transport.get_write_buffer_size = real  # type: ignore[method-assign]
            frames = await server.take(3)
            assert [f["msg"]["data"] for f in frames] == ["undock", "dock", "undock"]
            assert client.stats.sent == sent + 3

    run(main())


def test_held_publishes_leave_together_with_a_goal_or_at_release() -> None:
    """While held (the executive's tick), a publish waits; an urgent one (a goal) goes at
    once and takes those waiting before it in the same write; release writes the rest in
    one write. The order on the wire is the order of the calls."""

    async def main() -> None:
        rec = Recorder()
        async with FakeRosbridge() as server, client_for(server.url, rec) as client:
            client.advertise("/ICL_command", "std_msgs/String")
            client.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped")
            client.start()
            assert await client.wait_connected(5)
            await server.take(2)
            await client.flush(5)
            ws = client._ws
            assert ws is not None
            writes: list[int] = []  # the transport writes asked for (the frames are masked)
            transport = ws.transport
            real_write, real_writelines = transport.write, transport.writelines
            inside = [False]  # writelines may write through write (Python 3.11)

            def write(data: bytes) -> None:
                if not inside[0]:
                    writes.append(len(data))
                real_write(data)

            def writelines(chunks: list[bytes]) -> None:
                writes.append(sum(len(c) for c in chunks))
                inside[0] = True
                try:
                    real_writelines(chunks)
                finally:
                    inside[0] = False

            transport.write, transport.writelines = write, writelines  # type: ignore[method-assign]
            sent = client.stats.sent
            client.hold()
            client.publish("/ICL_command", encode_string("stop"))
            assert writes == [] and len(client._outbox) == 1  # held
            client.publish("/GotoWayPoint", encode_pose(1.0, 2.0, 0.0, 1.0, stamp=1.0), True)
            assert len(writes) == 1 and not client._outbox  # the goal took the stop along
            assert client.stats.sent == sent + 2
            client.publish("/ICL_command", encode_string("start"))
            client.publish("/ICL_command", encode_string("stop"))
            assert len(writes) == 1
            client.release()
            assert len(writes) == 2 and client.stats.sent == sent + 4  # both, in one write
            client.publish("/ICL_command", encode_string("start"))  # not held: at once
            assert len(writes) == 3
            frames = await server.take(5)
            assert [f["topic"] for f in frames] == [
                "/ICL_command",
                "/GotoWayPoint",
                "/ICL_command",
                "/ICL_command",
                "/ICL_command",
            ]
            assert [f["msg"].get("data") for f in frames] == [
                "stop",
                None,
                "start",
                "stop",
                "start",
            ]
            assert client.stats.sent == sent + 5

    run(main())


def test_subscribe_to_a_type_without_decoder_is_refused() -> None:
    client = RosbridgeClient("ws://127.0.0.1:9")
    with pytest.raises(ValueError, match="no decoder"):
        client.subscribe("/x", "sensor_msgs/Image")


@pytest.mark.parametrize("url", ["http://127.0.0.1:9090", "127.0.0.1:9090", "ws://"])
def test_bad_url_is_refused_at_construction(url: str) -> None:
    with pytest.raises(ValueError, match="rosbridge URL"):
        RosbridgeClient(url)


# ---------------------------------------------------------------- bad input


def test_malformed_inbound_frames_are_counted_and_the_client_keeps_working(
    caplog: pytest.LogCaptureFixture,
) -> None:
    async def main() -> None:
        rec = Recorder()
        async with FakeRosbridge() as server, client_for(server.url, rec) as client:
            client.subscribe("/FROG_response", "std_msgs/Int32")
            client.subscribe("/ICL_FaceDataStream", "frog_msgs/FaceData")
            client.start()
            await server.take(2)
            for frame in [
                "not json",
                "[1,2,3]",
                '{"op":"publish","topic":"/FROG_response"}',
                '{"op":"publish","topic":"/FROG_response","msg":{"data":"two"}}',
                '{"op":"publish","topic":"/FROG_response","msg":{"data":NaN}}',
                '{"op":"publish","topic":"/ICL_FaceDataStream","msg":{"faces":[{"id":1,'
                '"engagement":3,"distance":1,"facing":true}]}}',
                '{"op":"status","level":"error","msg":"something"}',
                '{"op":"service_response","service":"/x","values":{}}',
            ]:
                await server.push(frame)
            await server.push(b'{"op":"publish","topic":"/FROG_response","msg":{"data":4}}')
            assert await rec.messages.get() == ("/FROG_response", 4)
            stats = client.stats
            assert stats.received == 9 and stats.malformed == 6
            assert stats.malformed_by_topic == {
                FRAME_TOPIC: 4,
                "/FROG_response": 1,
                "/ICL_FaceDataStream": 1,
            }
            assert client.link.connected

    with caplog.at_level(logging.WARNING, logger="frog_bt.rosbridge.client"):
        run(main())
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    # rate limited: one warning per topic within the interval
    assert len([w for w in warnings if "malformed frame" in w]) == 1
    assert any("engagement" in w for w in warnings)
    assert any("msg.data: expected `int`" in w for w in warnings)


def test_on_message_exceptions_are_logged_not_fatal(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> None:
        seen: asyncio.Queue[int] = asyncio.Queue()

        def on_message(topic: str, value: Any) -> None:
            seen.put_nowait(value)
            if value == 1:
                raise RuntimeError("behaviour bug")

        async with FakeRosbridge() as server:
            client = RosbridgeClient(server.url, on_message=on_message, **FAST)
            client.subscribe("/FROG_response", "std_msgs/Int32")
            client.start()
            await server.take(1)
            await server.publish("/FROG_response", {"data": 1})
            await server.publish("/FROG_response", {"data": 2})
            assert [await seen.get(), await seen.get()] == [1, 2]
            assert client.link.connected
            await client.close()

    with caplog.at_level(logging.ERROR, logger="frog_bt.rosbridge.client"):
        run(main())
    assert any("on_message(/FROG_response) failed" in r.getMessage() for r in caplog.records)


def test_warning_throttle() -> None:
    throttle = WarningLimiter(interval=5.0)
    assert throttle.allow("/a", 100.0) == 0
    assert throttle.allow("/a", 101.0) is None
    assert throttle.allow("/a", 104.9) is None
    assert throttle.allow("/b", 104.9) == 0  # per key
    assert throttle.allow("/a", 105.0) == 2  # two held back since the last one
    assert throttle.allow("/a", 110.0) == 0


def test_backoff_doubles_up_to_the_cap() -> None:
    delays = backoff_delays(0.25, 5.0)
    assert [next(delays) for _ in range(8)] == [0.25, 0.5, 1.0, 2.0, 4.0, 5.0, 5.0, 5.0]


# ---------------------------------------------------------------- link loss


def test_reconnect_restores_advertise_subscribe_and_flushes_queue_in_order() -> None:
    async def main() -> None:
        rec = Recorder()
        server = await FakeRosbridge().start()
        async with client_for(server.url, rec) as client:
            client.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped")
            client.subscribe("/FROG_response", "std_msgs/Int32")
            client.start()
            first = await server.take(2)
            assert ops(first) == [("advertise", "/GotoWayPoint"), ("subscribe", "/FROG_response")]
            await rec.link(True)

            await server.stop()
            down = await rec.link(False)
            assert "1001" in (down.last_error or "")
            for i in range(3):  # made while down: queued in order
                client.publish("/GotoWayPoint", encode_pose(i, 0, 0, 1, stamp=1.0))
            assert client.queued == 3

            second = FakeRosbridge(port=server.port)
            await second.start()
            try:
                frames = await second.take(5)
                assert (
                    ops(frames)
                    == [("advertise", "/GotoWayPoint"), ("subscribe", "/FROG_response")]
                    + [("publish", "/GotoWayPoint")] * 3
                )
                assert [f["msg"]["pose"]["position"]["x"] for f in frames[2:]] == [0, 1, 2]
                assert frames[1]["type"] == "std_msgs/Int32"
                assert not {f["id"] for f in frames} & {f["id"] for f in first}
                up = await rec.link(True)
                assert up.reconnects == 1 and client.stats.reconnects == 1
                assert client.queued == 0 and client.stats.dropped == 0

                # and the new link carries inbound messages too
                await second.publish("/FROG_response", {"data": 2})
                assert await rec.messages.get() == ("/FROG_response", 2)
            finally:
                await client.close()
                await second.stop()

    run(main())


def test_queue_overflow_while_down_drops_oldest_with_a_count() -> None:
    async def main() -> None:
        rec = Recorder()
        server = await FakeRosbridge().start()
        async with client_for(server.url, rec, queue_limit=3) as client:
            client.advertise("/ApproachPeopleFar", "std_msgs/Int32")
            client.start()
            await server.take(1)
            await rec.link(True)
            await server.stop()
            await rec.link(False)
            for i in range(5):
                client.publish("/ApproachPeopleFar", encode_int32(i))
            assert client.stats.dropped == 2 and client.queued == 3

            second = await FakeRosbridge(port=server.port).start()
            try:
                frames = await second.take(4)
                assert ops(frames)[0] == ("advertise", "/ApproachPeopleFar")
                assert [f["msg"]["data"] for f in frames[1:]] == [2, 3, 4]
            finally:
                await client.close()
                await second.stop()

    run(main())


def test_publishes_before_the_first_connection_are_delivered() -> None:
    async def main() -> None:
        rec = Recorder()
        port = free_port()
        async with client_for(f"ws://127.0.0.1:{port}", rec) as client:
            client.advertise("/ICL_command", "std_msgs/String")
            client.publish("/ICL_command", encode_string("start"))
            client.start()
            assert not await client.wait_connected(0.05)  # nothing listens yet
            async with FakeRosbridge(port=port) as server:
                frames = await server.take(2)
                assert ops(frames) == [("advertise", "/ICL_command"), ("publish", "/ICL_command")]
                assert frames[1]["msg"] == {"data": "start"}
                assert (await rec.link(True)).reconnects == 0

    run(main())


def test_frames_not_yet_written_when_the_link_drops_are_requeued() -> None:
    # White box: the outbox holds frames the writer has not sent yet.
    client = RosbridgeClient("ws://127.0.0.1:9")
    client.advertise("/a", "std_msgs/Int32")
    client.subscribe("/b", "std_msgs/Int32")
    client.session.on_connected(0.0)
    client.session.connected = True
    for i in range(3):
        client.publish("/a", {"data": i})
    client.subscribe("/c", "std_msgs/String")
    client._on_down("test")
    assert client.queued == 3
    frames = [json.loads(f) for f in client.session.on_connected(1.0)]
    assert (
        ops(frames)
        == [("advertise", "/a"), ("subscribe", "/b"), ("subscribe", "/c")] + [("publish", "/a")] * 3
    )
    assert [f["msg"]["data"] for f in frames[3:]] == [0, 1, 2]


# ---------------------------------------------------------------- auth and link state


def test_auth_frame_is_sent_first_when_a_secret_is_configured() -> None:
    async def main() -> None:
        rec = Recorder()
        async with (
            FakeRosbridge() as server,
            client_for(server.url, rec, secret="s3cret") as client,
        ):
            client.advertise("/docking/dock", "std_msgs/String")
            client.subscribe("/docking/state", "std_msgs/String")
            client.start()
            auth, adv, sub = await server.take(3)
            assert ops([adv, sub]) == [
                ("advertise", "/docking/dock"),
                ("subscribe", "/docking/state"),
            ]
            assert auth["op"] == "auth"
            assert auth["client"] == "127.0.0.1" and auth["dest"] == "127.0.0.1"
            text = (
                f"s3cret{auth['client']}{auth['dest']}{auth['rand']}{int(auth['t'])}"
                f"{auth['level']}{int(auth['end'])}"
            )
            assert auth["mac"] == hashlib.sha512(text.encode()).hexdigest()

    run(main())


def test_link_state_callback_sequence() -> None:
    async def main() -> None:
        rec = Recorder()
        server = await FakeRosbridge().start()
        client = RosbridgeClient(server.url, on_link=rec.on_link, **FAST)
        assert client.link.connected is False and client.link.reconnects == 0
        client.start()
        assert await client.wait_connected(5)
        assert client.link.connected
        await rec.link(True)
        await server.stop()
        await rec.link(False)
        assert not await client.wait_connected(0)
        second = await FakeRosbridge(port=server.port).start()
        await rec.link(True)
        await client.close()
        await second.stop()
        await client.close()  # idempotent

        states = rec.link_log
        assert [(s.connected, s.reconnects) for s in states] == [
            (True, 0),
            (False, 0),
            (True, 1),
            (False, 1),
        ]
        assert states[0].last_error is None and states[2].last_error is None
        assert states[1].last_error is not None
        assert states[3].last_error is None  # a deliberate close is no error
        assert [s.since for s in states] == sorted(s.since for s in states)
        assert client.link == states[-1]

    run(main())


def test_nothing_listening_reports_the_error_and_close_stops_the_retries() -> None:
    async def main() -> None:
        rec = Recorder()
        failed = asyncio.Event()
        handler = logging.Handler()
        handler.emit = lambda record: failed.set()  # type: ignore[method-assign]
        handler.addFilter(lambda record: "cannot connect" in record.getMessage())
        logging.getLogger("frog_bt.rosbridge.client").addHandler(handler)
        try:
            client = RosbridgeClient(f"ws://127.0.0.1:{free_port()}", on_link=rec.on_link, **FAST)
            task = client.start()
            await failed.wait()
        finally:
            logging.getLogger("frog_bt.rosbridge.client").removeHandler(handler)
        assert not await client.wait_connected(0.05)
        assert client.link.connected is False and client.link.last_error
        assert client.stats.connect_failures >= 1
        await client.close()
        assert task.done() and task.exception() is None
        assert rec.link_log == []  # never up, so never a change of `connected`

    run(main())


def test_run_can_be_awaited_directly_and_close_ends_it() -> None:
    async def main() -> None:
        async with FakeRosbridge() as server:
            client = RosbridgeClient(server.url, **FAST)
            runner = asyncio.ensure_future(client.run())
            assert await client.wait_connected(5)
            await client.close()
            await runner  # returns normally, not cancelled
            assert not client.link.connected

    run(main())


def test_close_right_after_start() -> None:
    async def main() -> None:
        client = RosbridgeClient(f"ws://127.0.0.1:{free_port()}", **FAST)
        task = client.start()
        assert client.start() is task  # idempotent
        await client.close()
        assert task.done() and task.exception() is None

    run(main())


def test_a_server_that_closes_at_once_is_backed_off_and_reported_as_refused() -> None:
    """A refused auth is a close right after the handshake: the client must back off as
    for a refused connection, not reconnect at once for ever."""

    async def main() -> None:
        opened: list[float] = []
        enough = asyncio.Event()

        async def slam(ws) -> None:
            opened.append(asyncio.get_running_loop().time())
            if len(opened) >= 5:
                enough.set()
            await ws.close()

        async with serve(slam, "127.0.0.1", 0) as server:
            port = server.sockets[0].getsockname()[1]
            client = RosbridgeClient(
                f"ws://127.0.0.1:{port}", secret="s3cret", backoff_initial=0.05, backoff_max=0.4
            )
            client.start()
            await asyncio.wait_for(enough.wait(), 5)
            link = client.link
            await client.close()
        gaps = [b - a for a, b in itertools.pairwise(opened)]
        # 0.05, 0.1, 0.2, 0.4 s: doubling, never a tight loop
        assert [
            round(g, 2) >= d * 0.9 for g, d in zip(gaps, (0.05, 0.1, 0.2, 0.4), strict=False)
        ] == [True] * 4
        assert link.refused and not link.connected
        assert link.attempt >= 5 and "authentication refused?" in (link.last_error or "")

    run(main())


def test_a_connection_that_stays_up_restarts_the_backoff() -> None:
    async def main() -> None:
        rec = Recorder()
        server = await FakeRosbridge().start()
        client = RosbridgeClient(server.url, on_link=rec.on_link, stable_after=0.0, **FAST)
        client.start()
        await rec.link(True)
        await server.stop()
        await rec.link(False)
        down = client.link
        await client.close()
        assert down.attempt == 1 and not down.refused  # no secret, and a stable connection
        assert down.retry_in is not None and down.retry_in <= FAST["backoff_initial"]

    run(main())
