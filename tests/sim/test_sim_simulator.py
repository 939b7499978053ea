"""The simulator over real loopback sockets (port 0): rosbridge clients and a UDP executive."""

from __future__ import annotations

import asyncio
import itertools
import json
import time
from collections.abc import Awaitable, Callable
from typing import Any

import pytest
from sim_clients import Executive, RosClient
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

from frog_bt.model import frontend as fm
from frog_bt.rosbridge.protocol import auth_frame
from frog_bt.sim import Record, Simulator, load_scenario, parse_scenario
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.simulator import MAX_LAG

HOST = "127.0.0.1"
Run = Callable[[Awaitable[Any]], Any]


async def started(
    scenario: Scenario, run_clock: bool = True, **kwargs: Any
) -> tuple[Simulator, Executive]:
    exe = await Executive.open()
    sim = Simulator(
        scenario, rosbridge_port=0, frontend_port=0, executive=(HOST, exe.port), **kwargs
    )
    await sim.start(run_clock=run_clock)
    exe.frontend = (HOST, sim.frontend_port)
    return sim, exe


def fast(**data: Any) -> Scenario:
    data.setdefault("speed", 500)
    return parse_scenario(data)


def is_in(channel: str) -> Callable[[Record], bool]:
    return lambda r: r.direction == "in" and r.channel == channel


def test_rosbridge_by_hand_stepping(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(load_scenario("default"), run_clock=False)
        assert sim.rosbridge_port > 0 and sim.frontend_port > 0
        client = await RosClient.open(sim.rosbridge_port)
        await client.subscribe("/docking/state", "std_msgs/String")
        await client.subscribe("/clock")
        await client.send(op="advertise", id="a", topic="/docking/dock", type="std_msgs/String")
        await client.publish("/docking/dock", {"data": "undock"})
        await sim.wait_for(is_in("/docking/dock"), timeout=5)
        frame = await client.next(lambda f: f.get("topic") == "/docking/state")
        assert frame == {"op": "publish", "topic": "/docking/state", "msg": {"data": "undocking"}}
        start = sim.clock.now()
        sim.advance(5.0)
        assert sim.clock.now() == pytest.approx(start + 5.0)
        clock = await client.next_publish("/clock")
        assert clock == {"clock": {"secs": int(start), "nsecs": 100_000_000}}
        await client.next_publish("/docking/state", lambda m: m["data"] == "undocked")
        assert sim.world.docking_state == "undocked"
        assert [r.payload for r in sim.received("/docking/dock")] == [{"data": "undock"}]
        assert all(r.channel == "ack" for r in sim.received(side="frontend"))  # of the idle
        assert not any(r.channel == "/clock" for r in sim.log)
        await client.close()
        await sim.stop()
        exe.close()

    arun(main())


def test_the_clock_is_paced_and_never_runs_ahead(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast(speed=100))
        loop = asyncio.get_running_loop()
        client = await RosClient.open(sim.rosbridge_port)
        await client.subscribe("/clock")
        t0, w0 = sim.clock.now(), loop.time()
        stamps = []
        for _ in range(20):
            msg = await client.next_publish("/clock")
            stamps.append(msg["clock"]["secs"] + msg["clock"]["nsecs"] * 1e-9)
        steps = [b - a for a, b in itertools.pairwise(stamps)]
        assert all(s == pytest.approx(0.1, abs=1e-6) for s in steps)
        # ahead of the wall clock by at most the lag it may make up in a burst
        assert sim.clock.now() - t0 <= 100 * (loop.time() - w0 + MAX_LAG) + 0.2
        assert sim.running
        await client.close()
        await sim.stop()
        assert not sim.running
        exe.close()

    arun(main())


def test_two_clients_goal_response_and_forwarding(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast(robot={"docked": False, "pose": {"x": 0, "y": 0}}))
        executive, tool = (
            await RosClient.open(sim.rosbridge_port),
            await RosClient.open(sim.rosbridge_port),
        )
        await executive.subscribe("/FROG_response")
        await tool.subscribe("/GotoWayPoint")
        await tool.subscribe("/FROG_response")
        await tool.subscribe("/FROG_pose")
        await tool.next_publish("/FROG_pose")  # the server has the tool's subscriptions
        goal = {
            "header": {"seq": 0, "stamp": {"secs": 0, "nsecs": 0}, "frame_id": "map"},
            "pose": {
                "position": {"x": 1.0, "y": 0.0, "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
            },
        }
        await executive.publish("/GotoWayPoint", goal)
        assert await tool.next_publish("/GotoWayPoint") == goal
        for client in (executive, tool):
            assert await client.next_publish("/FROG_response") == {"data": 1}
            assert await client.next_publish("/FROG_response") == {"data": 2}
        await sim.wait_for(lambda r: r.payload == {"data": 2}, timeout=5)
        assert (sim.world.pose.x, sim.world.pose.y) == (1.0, 0.0)
        for client in (executive, tool):
            await client.close()
        await sim.stop()
        exe.close()

    arun(main())


def test_front_end_over_udp(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast(content={"introduction": 5}))
        assert await exe.events.get() == fm.FrontendIdle()
        await sim.wait_for(lambda r: r.side == "frontend" and r.channel == "ack", timeout=5)
        exe.send(fm.StartIntroduction(icl=False))
        assert await exe.events.get() == fm.FinishIntroduction()
        intro = sim.received("start_introduction", side="frontend")
        assert [r.payload for r in intro] == [{"icl": False}]
        done = await sim.wait_for(lambda r: r.channel == "finish_introduction", timeout=5)
        assert done.t - intro[0].t == pytest.approx(5.0, abs=0.11)
        assert exe.endpoint.pending == 0  # our command was acked
        await sim.stop()
        exe.close()

    arun(main())


def test_rosbridge_can_go_away_and_come_back(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast())
        port = sim.rosbridge_port
        client = await RosClient.open(port)
        await client.subscribe("/clock")
        await client.next_publish("/clock")
        await sim.stop_rosbridge()
        with pytest.raises(ConnectionClosed):
            while True:
                await client.ws.recv()
        with pytest.raises(OSError):
            await connect(f"ws://{HOST}:{port}", open_timeout=2)
        before = sim.clock.now()
        await sim.wait_for(lambda r: r.t > before + 1.0, timeout=5)  # time goes on
        await sim.start_rosbridge()
        assert sim.rosbridge_port == port
        again = await RosClient.open(port)
        await again.subscribe("/clock")
        msg = await again.next_publish("/clock")
        assert msg["clock"]["secs"] + msg["clock"]["nsecs"] * 1e-9 > before + 1.0
        await again.close()
        await sim.stop()
        exe.close()

    arun(main())


def test_a_secret_requires_auth(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast(), secret="s3cret")
        stranger = await RosClient.open(sim.rosbridge_port)
        await stranger.subscribe("/clock")
        with pytest.raises(ConnectionClosed) as info:
            while True:
                await stranger.ws.recv()
        assert info.value.rcvd is not None and info.value.rcvd.code == 1008
        friend = await RosClient.open(sim.rosbridge_port)
        # stamped with the wall clock, which rosauth compares with (not the sim's /clock)
        await friend.ws.send(json.dumps(auth_frame("s3cret", HOST, HOST, time.time())))
        await friend.subscribe("/clock")
        await friend.next_publish("/clock")
        assert sim.bridge.stats.auth_failures == 1
        await friend.close()
        await sim.stop()
        exe.close()

    arun(main())


def test_wait_for_gives_up_after_its_timeout(arun: Run) -> None:
    async def main() -> None:
        sim, exe = await started(fast(), run_clock=False)
        with pytest.raises(TimeoutError):
            await sim.wait_for(lambda r: r.channel == "/never", timeout=0.05)
        sim.step()
        first = await sim.wait_for(lambda r: r.channel == "/FROG_pose", timeout=0.05)
        assert first.side == "ros" and first.direction == "out"
        assert first.t == sim.clock.now()
        await sim.stop()
        exe.close()

    arun(main())
