"""The simulated robot behind a rosbridge server (``frog-bt sim --via``): a whole tour
through the built-in relaying server, and one through a server restart mid-tour."""

from __future__ import annotations

import asyncio
from collections import Counter
from typing import Any

from frog_bt.sim import Simulator
from frog_bt.sim.rosbridge_server import RosbridgeServer
from tests.e2e.tour import Running, fast, free_udp_port

HOST = "127.0.0.1"


def _start_pois(run: Running) -> Counter[tuple[str, str]]:
    return Counter((r.payload["poi"], r.payload["part"]) for r in run.sim.received("start_poi"))


async def _through_relay(restart: bool) -> dict[str, Any]:
    relay = RosbridgeServer.relay(HOST, 0)
    await relay.start()
    url = f"ws://{HOST}:{relay.port}"
    listen = (HOST, free_udp_port())
    sim = Simulator(fast(), via=url, frontend_port=0, executive=listen)
    await sim.start()
    try:
        async with Running({}, sim=sim, listen=listen, once=True) as run:
            if restart:
                await sim.wait_for(
                    lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI1", 60
                )
                await relay.stop()  # every client dropped: the executive and the robot
                await run.executive_ticks_until(lambda: not run.executive.client.link.connected)
                await relay.start()  # the same port
            outcome = await run.finish()
            return {
                "outcome": outcome,
                "commands": [c for c in run.tour().ros_commands()],
                "ended": [r.payload["state"] for r in sim.received("tour")],
                "starts": _start_pois(run),
                "via": sim._rosbridge,
                "relayed": relay.protocol.stats.publishes_in,
                "reconnects": run.executive.client.link.reconnects,
            }
    finally:
        await sim.stop()
        await relay.stop()


def test_a_whole_tour_runs_with_the_robot_behind_a_relaying_server() -> None:
    got = asyncio.run(_through_relay(restart=False))
    assert got["outcome"].code == 0, got["outcome"].reason
    assert got["commands"][0] == "/docking/dock undock"
    assert got["commands"][-1] == "/docking/dock dock"
    assert got["ended"] == ["started", "ended"]
    assert got["via"].received == len(got["commands"])  # every command, through the relay
    assert got["relayed"] > len(got["commands"])  # the robot's messages came that way too


def test_a_server_restart_mid_tour_is_reconnected_and_resubscribed() -> None:
    got = asyncio.run(_through_relay(restart=True))
    assert got["outcome"].code == 0, got["outcome"].reason
    assert got["via"].connections == 2  # the robot came back
    assert got["reconnects"] == 1  # and so did the executive
    assert got["ended"] == ["started", "ended"]  # the same tour, finished
    assert got["commands"][-1] == "/docking/dock dock"
    assert max(got["starts"].values()) == 1  # no content part started twice
