"""Replay speed: a recorded hour of simulated tours replayed offline, as a multiple of real time.

First records: the simulator and the executive in this process, on sim time as fast
as they go, tours back to back on the default scenario (real content lengths), with
``--record``'s :class:`~frog_bt.live.recording.Recorder`, until ``--minutes`` of simulated
time have passed. Then times ``frog-bt replay FILE.mcap`` in a fresh process, without
and with ``--rerun save:FILE.rrd``: the whole command (start-up included) and the
replay's own figure.

    .venv/bin/python scripts/bench_replay.py --minutes 60
"""

from __future__ import annotations

import argparse
import asyncio
import re
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
    emit,
    free_port,
    scenario,
    small_log,
)

REPLAYED = re.compile(r"replayed ([\d.]+) of ([\d.]+) s recorded in ([\d.]+) s wall")


async def record(path: Path, minutes: float, speed: float) -> dict[str, Any]:
    from frog_bt.behaviours import load_tree
    from frog_bt.clock import SimClock
    from frog_bt.config import load_site
    from frog_bt.live.recording import Recorder
    from frog_bt.rehearsal import links_to
    from frog_bt.runtime.executive import Executive
    from frog_bt.runtime.exits import ExitRules
    from frog_bt.runtime.observer import attach_all
    from frog_bt.sim import Simulator

    site = load_site()
    listen = (LOOPBACK, free_port())
    sim = Simulator(scenario({"speed": speed}), rosbridge_port=0, frontend_port=0, executive=listen)
    small_log(sim)
    await sim.start()
    clock = SimClock()
    executive = Executive(
        site, load_tree(site=site), clock, *links_to(sim, listen, clock), sim_time=True
    )
    rules = ExitRules()
    recorder = Recorder(path)
    attach_all(executive, [rules, recorder])
    end = sim.clock.now() + minutes * 60.0
    wall0 = time.monotonic()

    async def until_end() -> None:
        while sim.clock.now() < end:
            await asyncio.sleep(0.05)
        executive.stop("recorded enough")

    stopper = asyncio.ensure_future(until_end())
    try:
        await executive.run()
    finally:
        stopper.cancel()
        await sim.stop()
        recorder.close()
    return {
        "tours": rules.tours,
        "sim_s": minutes * 60.0,
        "wall_s": time.monotonic() - wall0,
        "messages": recorder.messages,
        "bytes": path.stat().st_size,
        "sim_dropped_frames": sim._rosbridge.dropped,
    }


def replay(path: Path, extra: list[str]) -> dict[str, Any]:
    t0 = time.perf_counter()
    done = subprocess.run(
        [str(FROG_BT), "replay", str(path), "--quiet", *extra], capture_output=True, text=True
    )
    wall = time.perf_counter() - t0
    match = REPLAYED.search(done.stdout)
    out: dict[str, Any] = {
        "exit": done.returncode,
        "command_wall_s": wall,
        "identical": done.stdout.startswith("identical"),
    }
    if match:
        covered, recorded, inner = (float(g) for g in match.groups())
        out.update(
            recorded_s=recorded,
            covered_s=covered,
            replay_wall_s=inner,
            speed_x=covered / max(inner, 1e-9),
            command_speed_x=covered / wall,
        )
    else:
        out["output"] = (done.stdout + done.stderr)[-2000:]
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=60.0, help="simulated minutes to record")
    p.add_argument("--speed", type=float, default=600.0, help="sim speed while recording")
    p.add_argument(
        "--copies",
        type=int,
        default=6,
        help="recordings in the batch corpus (copies of the recorded one)",
    )
    p.add_argument("--out")
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
        mcap = Path(tmp) / "tour.mcap"
        result: dict[str, Any] = {"recording": asyncio.run(record(mcap, args.minutes, args.speed))}
        result["plain"] = replay(mcap, [])
        result["rrd"] = replay(mcap, ["--rerun", f"save:{Path(tmp) / 'replay.rrd'}"])
        result["rrd"]["rrd_bytes"] = (
            (Path(tmp) / "replay.rrd").stat().st_size if (Path(tmp) / "replay.rrd").exists() else 0
        )
        result["batch"] = batch(mcap, Path(tmp) / "corpus", args.copies)
    emit(result, args.out)


def batch(mcap: Path, corpus: Path, copies: int) -> dict[str, Any]:
    """The corpus (``copies`` of the recording) with --jobs 1 and --jobs N (N = CPUs):
    recorded seconds replayed per wall second, and the ratio of the two."""
    import os
    import shutil

    corpus.mkdir()
    for i in range(copies):
        shutil.copy(mcap, corpus / f"tour-{i:02d}.mcap")
    recorded = 0.0
    match = REPLAYED.search(
        subprocess.run(
            [str(FROG_BT), "replay", str(mcap), "--quiet"], capture_output=True, text=True
        ).stdout
    )
    if match:
        recorded = float(match.group(2))
    jobs_n = os.cpu_count() or 1
    out: dict[str, Any] = {"copies": copies, "recorded_s_each": recorded, "cpus": jobs_n}
    for jobs in sorted({1, jobs_n}):
        t0 = time.perf_counter()
        done = subprocess.run(
            [str(FROG_BT), "replay", str(corpus), "--quiet", "--jobs", str(jobs)],
            capture_output=True,
            text=True,
        )
        wall = time.perf_counter() - t0
        out[f"jobs_{jobs}"] = {
            "exit": done.returncode,
            "wall_s": wall,
            "speed_x": copies * recorded / max(wall, 1e-9),
        }
    if jobs_n > 1:
        out["scaling"] = out[f"jobs_{jobs_n}"]["speed_x"] / max(out["jobs_1"]["speed_x"], 1e-9)
    return out


if __name__ == "__main__":
    main()
