"""SIGINT / SIGTERM halt the tree (face stream off, content stopped) and exit by themselves.

The 2 s the executive takes at most is the sum of its bounded shutdown waits (checked
below); the test measures no wall time, so a loaded machine cannot fail it.
"""

from __future__ import annotations

import asyncio
import signal
import sys

import pytest
from tour import fast, free_udp_port

from frog_bt.sim import Simulator


async def _signal_mid_content(sig: int) -> tuple[int, list[str]]:
    # a simulator not paced by the executive (it runs in another process): slow enough
    # that the signal comes while POI1's content plays, even on a loaded machine
    scenario = fast({"speed": 200.0})
    listen = free_udp_port()
    sim = Simulator(scenario, rosbridge_port=0, frontend_port=0, executive=("127.0.0.1", listen))
    await sim.start()
    try:
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "frog_bt",
            "run",
            "--sim-time",
            "--quiet",
            "--checkpoint",
            "none",
            "--rosbridge",
            f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend",
            f"127.0.0.1:{sim.frontend_port}",
            "--listen",
            f"127.0.0.1:{listen}",
        )
        await sim.wait_for(lambda r: r.channel == "start_poi" and r.payload["poi"] == "POI1", 60)
        t = sim.clock.now()
        proc.send_signal(sig)
        code = await asyncio.wait_for(proc.wait(), 60)  # a hang fails here, loudly
        after = [
            f"{r.channel} {r.payload.get('data', r.payload.get('poi', ''))}"
            for r in sim.received()
            if r.t >= t and r.channel not in ("ack", "engagement")
        ]
        return code, after
    finally:
        await sim.stop()


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_halts_the_tree_and_exits(sig):
    code, after = asyncio.run(_signal_mid_content(sig))
    assert code == 0
    assert "/ICL_command stop" in after  # face stream stopped
    assert "finish_poi POI1" in after  # content stopped


def test_the_shutdown_waits_fit_in_two_seconds():
    """Every wait of the shutdown is bounded; together they stay under 2 s."""
    from frog_bt.runtime.executive import FRONTEND_DRAIN, ROSBRIDGE_FLUSH

    assert FRONTEND_DRAIN + ROSBRIDGE_FLUSH < 2.0
