"""Start-up: from spawning ``frog-bt run`` to the executive connected and subscribed.

A fake rosbridge server (here, on loopback) notes when the new client has
subscribed to every input topic; the time from ``Popen`` to that frame coming off
the socket is the start-up time (interpreter, imports, configuration and tree
checks, UDP bind, WebSocket handshake, advertise and subscribe). Each run is
stopped with SIGTERM before the next. Also times the bare imports, for the record.

    .venv/bin/python scripts/bench_startup.py --runs 7
"""

from __future__ import annotations

import argparse
import asyncio
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import (
    FROG_BT,
    LOOPBACK,
    FakeFrontend,
    FakeRosbridge,
    emit,
    free_port,
    summary,
)


async def startup_runs(runs: int, extra: list[str]) -> dict[str, Any]:
    from frog_bt.model.wire import INPUTS

    server = FakeRosbridge(expect_subscriptions=len(INPUTS))
    await server.start()
    listen = free_port()
    frontend = FakeFrontend((LOOPBACK, listen))
    frontend_port = await frontend.open()
    times: list[float] = []
    try:
        for _ in range(runs):
            server.ready.clear()
            t0 = time.perf_counter_ns()
            proc = await asyncio.create_subprocess_exec(
                str(FROG_BT),
                "run",
                "--rosbridge",
                server.url,
                "--frontend",
                f"{LOOPBACK}:{frontend_port}",
                "--listen",
                f"{LOOPBACK}:{listen}",
                "--checkpoint",
                "none",
                "--quiet",
                *extra,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            try:
                await asyncio.wait_for(server.ready.wait(), 30)
                times.append((server.ready_ns - t0) / 1e9)
            finally:
                proc.send_signal(signal.SIGTERM)
                await asyncio.wait_for(proc.wait(), 30)
    finally:
        frontend.close()
        await server.stop()
    return summary(times)


def import_time() -> float:
    """Seconds for a fresh interpreter to import what ``frog-bt run`` needs."""
    code = (
        "import frog_bt.commands.run, frog_bt.runtime.executive, frog_bt.runtime.status; "
        "from frog_bt.config import load_site; from frog_bt.behaviours import load_tree; "
        "load_tree(site=load_site())"
    )
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    loaded = time.perf_counter() - t0
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    return loaded - (time.perf_counter() - t0)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=7)
    p.add_argument(
        "--telemetry", action="store_true", help="also time a start with --record and --rerun save:"
    )
    p.add_argument("--out")
    args = p.parse_args()
    result: dict[str, Any] = {"runs": args.runs}
    result["plain"] = asyncio.run(startup_runs(args.runs, []))
    if args.telemetry:
        with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
            result["telemetry"] = asyncio.run(
                startup_runs(
                    max(2, args.runs // 2),
                    ["--record", f"{tmp}/s.mcap", "--rerun", f"save:{tmp}/s.rrd"],
                )
            )
    result["imports_and_checks_s"] = min(import_time() for _ in range(3))
    emit(result, args.out)


if __name__ == "__main__":
    main()
