"""The executive on the wire: advertise and subscribe first, unsubscribe and unadvertise last."""

from __future__ import annotations

import asyncio
from typing import Any

from links import over_sockets

from frog_bt.behaviours import load_tree
from frog_bt.clock import WallClock
from frog_bt.config import load_site
from frog_bt.model.wire import INPUTS, OUTPUTS
from frog_bt.rehearsal import free_udp_port

from .conftest import FakeRosbridge


async def _ops() -> list[dict[str, Any]]:
    site = load_site()
    async with FakeRosbridge() as server:
        executive = over_sockets(
            site,
            load_tree(site=site),
            WallClock(),
            url=server.url,
            frontend=("127.0.0.1", free_udp_port()),
            listen=("127.0.0.1", free_udp_port()),
        )
        run = asyncio.create_task(executive.run())
        await asyncio.wait_for(executive.client.wait_connected(), 5)
        while len([f for f in server.frames if f["op"] == "subscribe"]) < len(INPUTS):
            await asyncio.wait_for(server.next_frame(), 5)  # frames arrive in order
        executive.stop("test over")
        await asyncio.wait_for(run, 5)
        return list(server.frames)


def test_ops_in_order_each_with_an_id():
    frames = asyncio.run(_ops())
    ops = [f["op"] for f in frames]
    n_in, n_out = len(INPUTS), len(OUTPUTS)
    assert ops == (
        ["advertise"] * n_out
        + ["subscribe"] * n_in
        + ["unsubscribe"] * n_in
        + ["unadvertise"] * n_out
    )
    assert all(isinstance(f.get("id"), str) and f["id"] for f in frames)
    assert {f["topic"] for f in frames if f["op"] == "subscribe"} == {
        t.name for t in INPUTS.values()
    }
    assert {(f["topic"], f["type"]) for f in frames if f["op"] == "advertise"} == {
        (t.name, t.type) for t in OUTPUTS.values()
    }
