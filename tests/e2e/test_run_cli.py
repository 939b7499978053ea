"""`frog-bt run` as outside tools drive it (CONTRACT §5): a subprocess against the simulator."""

from __future__ import annotations

import asyncio
import subprocess
import sys

from tour import fast, free_udp_port

from frog_bt.sim import Simulator


async def _run_once() -> tuple[int, bytes, list[str]]:
    scenario = fast()
    listen = free_udp_port()
    sim = Simulator(scenario, rosbridge_port=0, frontend_port=0, executive=("127.0.0.1", listen))
    await sim.start()
    try:
        proc = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "frog_bt", "run", "--sim-time", "--once", "--quiet",
            "--checkpoint", "none",
            "--rosbridge", f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend", f"127.0.0.1:{sim.frontend_port}", "--listen", f"127.0.0.1:{listen}",
            stderr=asyncio.subprocess.PIPE)
        _, stderr = await asyncio.wait_for(proc.communicate(), 90)
        tours = [r.payload["state"] for r in sim.received("tour")]
        return proc.returncode or 0, stderr, tours
    finally:
        await sim.stop()


def test_run_once_exits_0_after_one_tour_ends_docked():
    code, stderr, tours = asyncio.run(_run_once())
    assert code == 0, stderr.decode()
    assert tours == ["started", "ended"]


def test_bad_config_is_one_line_and_exit_2(tmp_path):
    bad = tmp_path / "site.yaml"
    bad.write_text("pois: {}\ntour: {stops: [{poi: POI1}]}\n")
    result = subprocess.run([sys.executable, "-m", "frog_bt", "run", "--config", str(bad)],
                            capture_output=True, text=True, timeout=30)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"frog-bt: {bad}: tour.dock: unknown POI 'SHOP' (no POIs are defined)"]
