"""Case 3: bad input on both links — counted, logged (rate-limited), never fatal.

Outcome: malformed JSON, wrong types, NaN and Infinity, missing fields, unknown
ops and message types, oversized frames, engagement outside [-1, 1], datagrams
from other hosts: each is dropped and counted (``RosbridgeClient.stats``:
``malformed`` / ``ignored``; ``FrontendLink.stats``: ``malformed`` /
``duplicates`` / ``foreign``), warned about at most once per kind every 5 s
(wall), and changes nothing: the executive keeps ticking and sends nothing it
would not have sent anyway.

More than 100,000 generated frames in all: the decoders alone, then a running
executive flooded on every subscribed topic and on its UDP port.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import json
import logging
import math
import socket
import time
from collections import Counter
from typing import Any

import pytest
from garbage import (
    TOPIC_TYPES,
    VALID_FIELDS,
    VALID_MSGS,
    Garbage,
    classify_datagram,
    classify_frame,
)
from hypothesis import given, settings
from hypothesis import strategies as st
from links import over_sockets
from rosmsgs import DECODERS, encode_clock
from websockets.asyncio.server import ServerConnection, serve

from frog_bt.behaviours import load_tree
from frog_bt.clock import SimClock
from frog_bt.config import load_site
from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import Endpoint, decode_datagram, encode_datagram
from frog_bt.model import frontend as fm
from frog_bt.rehearsal import free_udp_port
from frog_bt.rosbridge.protocol import Publish, decode_frame
from frog_bt.warning_limit import WARN_INTERVAL

ROS_FRAMES = 70_000  # through decode_frame and the message decoders
ROS_MSGS = 20_000  # mutated msg objects straight into the decoders (NaN as a float)
DATAGRAMS = 30_000  # through decode_datagram and both sides' Endpoint
LIVE_FRAMES = 24_000  # to a running executive over rosbridge
LIVE_DATAGRAMS = 6_000  # to a running executive over UDP, from the front end's host
LIVE_FOREIGN = 1_000  # ... and from another host
PEER, STRANGER = "127.0.0.1", "127.0.0.2"


def sane(value: Any, path: str = "") -> None:
    """Every number in a decoded value is finite; engagement and orientation in range."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            sane(getattr(value, f.name), f"{path}.{f.name}")
        if hasattr(value, "engagement"):
            assert -1.0 <= value.engagement <= 1.0 and value.distance >= 0, path
        if hasattr(value, "orientation"):
            assert 0.0 <= value.orientation <= 360.0, path
    elif isinstance(value, tuple):
        for i, item in enumerate(value):
            sane(item, f"{path}[{i}]")
    elif isinstance(value, float):
        assert math.isfinite(value), path
    elif isinstance(value, int) and not isinstance(value, bool):
        assert -(2**32) <= value < 2**32, path


# ------------------------------------------------------------------ the decoders alone


def test_rosbridge_decoders_accept_or_raise_decode_error() -> None:
    g, outcomes = Garbage(seed=1), Counter[str]()
    for frame in g.frames(ROS_FRAMES):
        try:
            event = decode_frame(frame)
        except DecodeError:
            outcomes["frame"] += 1
            continue
        if not isinstance(event, Publish) or event.topic not in TOPIC_TYPES:
            outcomes["other"] += 1
            continue
        try:
            sane(DECODERS[TOPIC_TYPES[event.topic]](event.msg))
            outcomes["valid"] += 1
        except DecodeError:
            outcomes["msg"] += 1
    texts = {type_: json.dumps(msg) for type_, msg in VALID_MSGS.items()}
    for i in range(ROS_MSGS):
        type_ = list(texts)[i % len(texts)]
        try:
            sane(DECODERS[type_](g.mutate(json.loads(texts[type_]))))
            outcomes["valid"] += 1
        except DecodeError:
            outcomes["msg"] += 1
    assert sum(outcomes.values()) == ROS_FRAMES + ROS_MSGS
    assert min(outcomes.values()) > 1000, outcomes  # every path well exercised


def test_frontend_decoders_accept_or_raise_decode_error() -> None:
    g, outcomes = Garbage(seed=2), Counter[str]()
    executive, front_end = Endpoint(PEER, fm.EVENTS), Endpoint(PEER, fm.COMMANDS)
    for i, data in enumerate(g.datagrams(DATAGRAMS)):
        try:
            decode_datagram(data)
            outcomes["datagram"] += 1
        except DecodeError:
            outcomes["bad"] += 1
        for ep in (executive, front_end):
            got = ep.receive(data, PEER if i % 10 else STRANGER, float(i))
            if got.message is not None:  # whatever is accepted is a clean, encodable value
                encode_datagram(got.message.type, 1, fm.message_fields(got.message))
    assert sum(outcomes.values()) == DATAGRAMS and min(outcomes.values()) > 1000, outcomes
    for ep in (executive, front_end):
        s = ep.stats
        assert s.foreign == DATAGRAMS // 10
        assert s.received + s.malformed + s.duplicates + s.foreign + s.acked <= DATAGRAMS
        assert s.malformed > DATAGRAMS // 2


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=8,
)


def _replace_somewhere(obj: Any, path: list[int], value: Any) -> Any:
    """``obj`` with the node that ``path`` picks (indices into children) set to ``value``."""
    if not path or not isinstance(obj, dict | list) or not obj:
        return value
    keys = list(obj) if isinstance(obj, dict) else list(range(len(obj)))
    key = keys[path[0] % len(keys)]
    obj[key] = _replace_somewhere(obj[key], path[1:], value)
    return obj


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(sorted(VALID_MSGS)), st.lists(st.integers(0, 9), max_size=6), JSON)
def test_a_valid_message_with_any_value_anywhere(type_: str, path: list[int], value: Any) -> None:
    msg = _replace_somewhere(json.loads(json.dumps(VALID_MSGS[type_])), path, value)
    with contextlib.suppress(DecodeError):
        sane(DECODERS[type_](msg))


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(sorted(VALID_FIELDS)), st.lists(st.integers(0, 9), max_size=3), JSON)
def test_a_valid_datagram_with_any_value_anywhere(type_: str, path: list[int], value: Any) -> None:
    obj = _replace_somewhere({"type": type_, "seq": 3, **VALID_FIELDS[type_]}, path, value)
    data = json.dumps(obj).encode("utf-8", "surrogatepass")
    for table in (fm.EVENTS, fm.COMMANDS):
        got = Endpoint(PEER, table).receive(data, PEER, 0.0)
        if got.message is not None:
            encode_datagram(got.message.type, 1, fm.message_fields(got.message))


# ------------------------------------------------------------------ a running executive


async def until(condition: Any, what: str, timeout: float = 60.0) -> None:
    """Let the event loop run until ``condition()`` holds (frames in flight are handled)."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        await asyncio.sleep(0.001)


def test_running_executive_survives_a_flood_of_bad_input(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING)
    site = load_site()
    g = Garbage(seed=3)

    windows: list[int] = []  # the limiter's intervals the flood lasted

    async def main() -> None:
        from_executive: list[dict[str, Any]] = []
        subscribed = asyncio.Event()
        connections: list[ServerConnection] = []

        async def handler(ws: ServerConnection) -> None:
            connections.append(ws)
            async for text in ws:  # the executive closes cleanly (1000) at the end
                from_executive.append(json.loads(text))
                if sum(f["op"] == "subscribe" for f in from_executive) == len(TOPIC_TYPES):
                    subscribed.set()

        front_end = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        peer = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        stranger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for sock, host in ((front_end, PEER), (peer, PEER), (stranger, STRANGER)):
            sock.bind((host, 0))
            sock.setblocking(False)
        async with serve(handler, "127.0.0.1", 0) as server:
            port = server.sockets[0].getsockname()[1]
            listen = ("127.0.0.1", free_udp_port())
            exe = over_sockets(
                site,
                load_tree(site=site),
                SimClock(),
                url=f"ws://127.0.0.1:{port}",
                frontend=front_end.getsockname(),
                listen=listen,
                sim_time=True,
            )
            task = asyncio.create_task(exe.run())
            await asyncio.wait_for(subscribed.wait(), 10)
            (ws,) = connections
            t = 1_780_000_000.0
            await ws.send(json.dumps({"op": "publish", "topic": "/clock", "msg": encode_clock(t)}))
            await until(lambda: exe.core.ticks > 0, "the first tick")
            ticks = exe.core.ticks
            began = time.monotonic()  # the limiter's interval is wall time
            expected, pushed = Counter[str](), 1
            local = foreign = 0
            batches = LIVE_FRAMES // 200
            for _ in range(batches):
                sent = 0
                while sent < 200:
                    frame = g.frame()
                    kind = classify_frame(frame, TOPIC_TYPES)
                    if kind == "valid":
                        continue  # a mutation that left it valid: not bad input
                    expected[kind] += 1
                    await ws.send(frame)
                    sent += 1
                t += 0.1  # a good /clock now and then: the tree keeps ticking
                await ws.send(
                    json.dumps({"op": "publish", "topic": "/clock", "msg": encode_clock(t)})
                )
                pushed += 201
                for data in g.datagrams(LIVE_DATAGRAMS // batches):
                    if classify_datagram(data, fm.EVENTS) == "malformed":
                        peer.sendto(data[:65000], listen)
                        local += 1
                # from another host, even valid events (frontend_idle would start a tour)
                for i in range(LIVE_FOREIGN // batches):
                    data = encode_datagram("frontend_idle", i + 1) if i % 2 else g.datagram()
                    stranger.sendto(data[:65000], listen)
                    foreign += 1
                s, want = exe.link.stats, local + foreign
                await until(
                    lambda s=s, want=want: s.malformed + s.duplicates + s.foreign >= want,
                    "the datagrams to be counted",
                )
            await until(lambda: exe.client.stats.received >= pushed, "the frames to be read")

            # Still ticking, every bad frame and datagram counted, nothing acted on.
            await until(lambda: exe.core.ticks >= ticks + batches // 2, "ticks")
            assert not task.done()
            stats = exe.client.stats
            assert stats.received == pushed
            assert stats.malformed == expected["malformed"]
            assert stats.ignored == expected["ignored"]
            assert set(stats.malformed_by_topic) >= set(TOPIC_TYPES) | {"<frame>"}
            s = exe.link.stats
            assert s.malformed + s.duplicates == local and s.foreign == foreign
            assert s.received == 0 and s.sent == 0 and s.peer_restarts == 0
            exe.stop("test over")
            assert (await asyncio.wait_for(task, 10)).code == 0
            windows.append(math.floor((time.monotonic() - began) / WARN_INTERVAL) + 1)
            assert not list(exe.core.inputs.events)
        # It advertised and subscribed, and sent nothing else but its goodbyes at the
        # shutdown (unsubscribe, unadvertise): no tour began.
        ops = Counter(f["op"] for f in from_executive)
        assert ops == {
            "advertise": 4,
            "subscribe": len(TOPIC_TYPES),
            "unadvertise": 4,
            "unsubscribe": len(TOPIC_TYPES),
        }, ops
        with pytest.raises(BlockingIOError):
            front_end.recv(65536)  # no command to the front end either
        for sock in (front_end, peer, stranger):
            sock.close()
        total = pushed + local + foreign
        records = [r for r in caplog.records if r.levelno >= logging.WARNING]
        assert not [r for r in records if r.levelno >= logging.ERROR]
        # at most one warning per kind (topic, foreign, malformed) per 5 s of wall time,
        # however long a loaded machine took over the flood
        (n,) = windows
        assert len(records) < 40 * n and len(records) * 500 < total * n, [
            r.getMessage()[:100] for r in records
        ]

    asyncio.run(main())  # how fast is measured in scripts/bench, not here


def test_enough_generated_input_in_all() -> None:
    live = LIVE_FRAMES + LIVE_DATAGRAMS + LIVE_FOREIGN
    assert ROS_FRAMES + ROS_MSGS + DATAGRAMS + live >= 100_000
