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
import os
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


async def startup_runs(
    runs: int, extra: list[str], importtime: Path | None = None
) -> dict[str, Any]:
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
                stderr=subprocess.DEVNULL if importtime is None else importtime.open("wb"),
                env={**os.environ, "PYTHONPROFILEIMPORTTIME": "1"} if importtime else None,
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


def import_table(log: Path, top: int = 25) -> dict[str, Any]:
    """What ``-X importtime`` wrote up to the subscription: the total of the top-level
    imports (cumulative), and each package's own import time (its modules' self times
    summed: numpy, pydantic, frog_bt ...), dearest first, in seconds."""
    total = 0
    own: dict[str, int] = {}
    modules = 0
    for line in log.read_text(errors="replace").splitlines():
        if not line.startswith("import time:") or "cumulative" in line:
            continue
        self_us, cum_us, name = line.split(":", 1)[1].split("|")
        if not name.startswith("  "):  # a top-level import has one space before its name
            total += int(cum_us)
        package = name.strip().split(".")[0]
        own[package] = own.get(package, 0) + int(self_us)
        modules += 1
    dearest = sorted(own.items(), key=lambda kv: -kv[1])[:top]
    return {
        "total_s": total / 1e6,
        "modules": modules,
        "packages_self_s": {k: round(v / 1e6, 4) for k, v in dearest},
    }


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


def compile_bytecode() -> str:
    """frog_bt's modules compiled to ``__pycache__`` as an installed package has them (pip
    compiles at install). Under ``PYTHONDONTWRITEBYTECODE=1`` (set on the machine these
    figures come from) an editable install never writes them, and every start compiled
    frog_bt's ~110 modules from source: +0.07-0.17 s (docs/PERFORMANCE.md). Where
    frog_bt is imported from (``PYTHONPATH=DIR`` for the code before a change)."""
    import compileall

    import frog_bt

    package = Path(frog_bt.__file__).parent
    compileall.compile_dir(str(package), quiet=1)
    return str(package)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=7)
    p.add_argument(
        "--source",
        action="store_true",
        help="do not compile frog_bt's bytecode first (a start then may compile from source)",
    )
    p.add_argument(
        "--telemetry", action="store_true", help="also time a start with --record and --rerun save:"
    )
    p.add_argument(
        "--importtime",
        type=Path,
        metavar="LOG",
        help="instead: one start under -X importtime (telemetry on with --telemetry), its "
        "log kept in LOG, and the top-level imports summed by package",
    )
    p.add_argument("--out")
    args = p.parse_args()
    compiled = None if args.source else compile_bytecode()
    if args.importtime is not None:
        with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
            extra = ["--record", f"{tmp}/s.mcap", "--rerun", f"save:{tmp}/s.rrd"]
            asyncio.run(startup_runs(1, extra if args.telemetry else [], args.importtime))
        emit(import_table(args.importtime), args.out)
        return
    result: dict[str, Any] = {"runs": args.runs, "bytecode_compiled": compiled}
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
