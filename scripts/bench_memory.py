"""Memory of the executive over simulated tours back to back: RSS after the first and the last.

The executive runs in a process of its own (``bench_executive.py``, on sim time) so
that its resident set is its own; the simulator runs here, on a scenario with a fast
robot and short content so that a tour takes a few seconds of wall time. The
executive reports its RSS each time a tour ends.

    .venv/bin/python scripts/bench_memory.py --tours 100
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import (
    LOOPBACK,
    SCRIPTS,
    SITE_FILE,
    Child,
    emit,
    free_port,
    scenario,
)

# One visitor who says yes and comes back after every tour; a fast robot, short content.
FAST_TOURS: dict[str, Any] = {
    "navigation": {"speed": 3.0, "approach_time": 1.0},
    "docking": {"undock_time": 2.0, "dock_time": 3.0},
    "content": {"default": 4, "introduction": 3},
    "frontend": {"idle_at": 1.0, "idle_after_tour": 1.0, "answer_delay": 1.0},
}


async def measure(tours: int, speed: float, telemetry: str, workdir: Path) -> dict[str, Any]:
    from frog_bt.sim import Simulator

    listen = (LOOPBACK, free_port())
    sim = Simulator(
        scenario({**FAST_TOURS, "speed": speed}),
        host=LOOPBACK,
        rosbridge_port=0,
        frontend_port=0,
        executive=listen,
    )
    await sim.start()
    argv: list[Any] = [
        sys.executable,
        SCRIPTS / "bench_executive.py",
        "--config",
        SITE_FILE,
        "--rosbridge",
        f"ws://{LOOPBACK}:{sim.rosbridge_port}",
        "--frontend",
        f"{LOOPBACK}:{sim.frontend_port}",
        "--listen",
        f"{LOOPBACK}:{listen[1]}",
        "--sim-time",
    ]
    if telemetry in ("on", "record"):
        argv += ["--record", workdir / "recordings"]  # one file per tour, as on the robot
    if telemetry in ("on", "rerun"):
        argv += ["--rerun", f"save:{workdir / 'memory.rrd'}"]
    sim0, wall0 = sim.clock.now(), time.monotonic()
    child = await Child.start(*argv)
    marks: list[dict[str, Any]] = []
    try:
        while len(marks) < tours:
            marks.append(await child.expect("tour", timeout=120))
    finally:
        await child.finish()
        await sim.stop()
    first, last = marks[0], marks[-1]
    return {
        "tours": len(marks),
        "speed": speed,
        "telemetry": telemetry,
        "sim_s": sim.clock.now() - sim0,
        "wall_s": time.monotonic() - wall0,
        "rss_first_kb": first["rss_kb"],
        "rss_last_kb": last["rss_kb"],
        "growth_pct": 100.0 * (last["rss_kb"] - first["rss_kb"]) / first["rss_kb"],
        "hwm_kb": last.get("hwm_kb"),
        "rss_kb_by_tour": [m["rss_kb"] for m in marks],
        "growth_from_tour_10_pct": 100.0
        * (last["rss_kb"] - marks[min(9, len(marks) - 1)]["rss_kb"])
        / marks[min(9, len(marks) - 1)]["rss_kb"],
        "child_rss_kb_by_tour": [m.get("child_rss_kb", 0) for m in marks],
        "sim_dropped_frames": sim._rosbridge.dropped,
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tours", type=int, default=100)
    p.add_argument("--speed", type=float, default=300.0, help="sim-time speed factor")
    p.add_argument(
        "--telemetry",
        choices=("on", "off", "record", "rerun"),
        default="off",
        help="on: --record DIR and --rerun save:FILE.rrd; or either alone",
    )
    p.add_argument("--out")
    args = p.parse_args()
    import tempfile

    with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
        result = asyncio.run(measure(args.tours, args.speed, args.telemetry, Path(tmp)))
    emit(result, args.out)


if __name__ == "__main__":
    main()
