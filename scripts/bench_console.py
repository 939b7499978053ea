#!/usr/bin/env python3
"""What the operator's console costs: tick p50 with the console off, and on with 10 pages
(WebSocket clients) connected; and how long a new phase takes to reach the pages.

    .venv/bin/python scripts/bench_console.py [--clients 10] [--runs 3]

Each run is one whole simulated tour of the default scenario at 50x (sim time). The tick
is timed with the thread's CPU time (as scripts/bench_ticks.py does); the latency is wall
time from the tick that changed the phase to each page receiving a state with it.
Goals (issue 20): tick p50 +5 % at most, a change on the page within 0.5 s.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import time
from typing import Any

import aiohttp
from bench_support import emit

from frog_bt.commands.console_options import ConsoleSettings, start_people
from frog_bt.config import load_site
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.status import phase
from frog_bt.sim import scenario_from


async def one(clients: int) -> dict[str, Any]:
    site = load_site()
    rehearsal = Rehearsal(scenario_from("default", {"speed": 50.0}), site=site, once=True)
    ticks: list[int] = []
    changes: dict[str, float] = {}  # phase -> wall time of the tick that began it
    seen: list[float] = []
    async with rehearsal:
        exe = rehearsal.executive
        inner = exe.core.tick

        def timed() -> Any:
            t0 = time.thread_time_ns()
            status = inner()
            ticks.append(time.thread_time_ns() - t0)
            name = phase(exe.core)
            if name not in changes:
                changes[name] = time.monotonic()
            return status

        exe.core.tick = timed  # type: ignore[method-assign]
        people = None
        tasks: list[asyncio.Task[None]] = []
        if clients:
            people = await start_people(exe, ConsoleSettings("127.0.0.1", 0, None), [])
            assert people.console is not None
            url = f"http://127.0.0.1:{people.console.bound_port}/api/stream"

            async def page() -> None:
                last = None
                async with aiohttp.ClientSession() as s, s.ws_connect(url) as ws:
                    async for msg in ws:
                        now = time.monotonic()
                        name = json.loads(msg.data)["phase"]
                        if name != last and name in changes:
                            seen.append(now - changes[name])
                        last = name

            tasks = [asyncio.create_task(page()) for _ in range(clients)]
        await rehearsal.finish(300.0)
        for task in tasks:
            task.cancel()
        if people is not None:
            await people.close()
    return {
        "tick_p50_us": statistics.median(ticks) / 1000,
        "ticks": len(ticks),
        "latency_ms": [round(1000 * s, 1) for s in seen],
    }


async def main(clients: int, runs: int, out: str | None = None) -> None:
    off, on, latency = [], [], []
    for _ in range(runs):  # alternate, so that load drifts hit both alike
        off.append((await one(0))["tick_p50_us"])
        result = await one(clients)
        on.append(result["tick_p50_us"])
        latency += result["latency_ms"]
    p50_off, p50_on = statistics.median(off), statistics.median(on)
    print(f"tick p50, console off: {p50_off:.1f} us (runs {', '.join(f'{x:.1f}' for x in off)})")
    print(
        f"tick p50, console on with {clients} pages: {p50_on:.1f} us "
        f"(runs {', '.join(f'{x:.1f}' for x in on)}): {100 * (p50_on / p50_off - 1):+.1f} %"
    )
    if latency:
        latency.sort()
        print(
            f"new phase to page: p50 {statistics.median(latency):.1f} ms, "
            f"max {latency[-1]:.1f} ms over {len(latency)} deliveries"
        )
    emit(
        {
            "clients": clients,
            "runs": runs,
            "tick_p50_off_us": p50_off,
            "tick_p50_on_us": p50_on,
            "overhead_pct": 100 * (p50_on / p50_off - 1),
            "latency_p50_ms": statistics.median(latency) if latency else None,
            "latency_max_ms": latency[-1] if latency else None,
            "deliveries": len(latency),
        },
        out,
    )


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--clients", type=int, default=10)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--out", help="write the figures as JSON here")
    a = p.parse_args()
    asyncio.run(main(a.clients, a.runs, a.out))
