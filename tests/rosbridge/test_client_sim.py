"""RosbridgeClient against the built-in simulator: the real pair, end to end, on loopback
and over an in-memory wire (frog_bt/rosbridge/memory.py), which must behave the same."""

from __future__ import annotations

import asyncio

import pytest
from rosmsgs import encode_pose

from frog_bt.model.ros import Pose
from frog_bt.rosbridge.client import RosbridgeClient
from frog_bt.sim import Simulator, parse_scenario


async def _drive_and_reconnect(memory: bool) -> tuple[list[int], int, int, int]:
    sim = Simulator(
        parse_scenario({"speed": 100.0, "robot": {"docked": False}}),
        rosbridge_port=0,
        frontend_port=0,
        memory=memory,
    )
    await sim.start()
    poses: asyncio.Queue[Pose] = asyncio.Queue()
    responses: asyncio.Queue[int] = asyncio.Queue()

    def on_message(topic: str, value: object) -> None:
        if topic == "/FROG_pose":
            poses.put_nowait(value)  # type: ignore[arg-type]
        elif topic == "/FROG_response":
            responses.put_nowait(value)  # type: ignore[arg-type]

    down = asyncio.Event()
    client = RosbridgeClient(
        sim.wire.url if sim.wire else f"ws://127.0.0.1:{sim.rosbridge_port}",
        connect=sim.wire.connect if sim.wire else None,
        on_message=on_message,
        on_link=lambda state: None if state.connected else down.set(),
        backoff_initial=0.05,
        backoff_max=0.2,
    )
    client.subscribe("/FROG_pose", "geometry_msgs/PoseStamped")
    client.subscribe("/FROG_response", "std_msgs/Int32")
    client.advertise("/GotoWayPoint", "geometry_msgs/PoseStamped")
    client.start()
    try:
        assert await client.wait_connected(5)
        start = await asyncio.wait_for(poses.get(), 5)
        client.publish(
            "/GotoWayPoint", encode_pose(start.x + 1.0, start.y, 0.0, 1.0, sim.clock.now())
        )
        codes = [await asyncio.wait_for(responses.get(), 5) for _ in range(2)]

        await sim.stop_rosbridge()  # the robot's rosbridge goes away...
        await asyncio.wait_for(down.wait(), 5)
        await sim.start_rosbridge()  # ...and comes back: the client resubscribes by itself
        assert await client.wait_connected(5)
        while not poses.empty():
            poses.get_nowait()
        await asyncio.wait_for(poses.get(), 5)  # poses flow again: resubscribed
        client.publish("/GotoWayPoint", encode_pose(start.x, start.y, 0.0, 1.0, sim.clock.now()))
        codes += [await asyncio.wait_for(responses.get(), 5) for _ in range(2)]
        gotos = len(sim.received("/GotoWayPoint"))
        return codes, client.link.reconnects, gotos, client.stats.malformed
    finally:
        await client.close()
        await sim.stop()


@pytest.mark.parametrize("memory", [False, True], ids=["socket", "memory"])
def test_subscribe_publish_and_resubscribe_after_the_server_restarts(memory: bool):
    codes, reconnects, gotos, malformed = asyncio.run(_drive_and_reconnect(memory))
    assert codes == [1, 2, 1, 2]
    assert reconnects == 1
    assert gotos == 2
    assert malformed == 0
