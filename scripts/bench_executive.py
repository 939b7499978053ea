"""The executive under test, in a process of its own, reporting on stdout as JSON lines.

Built as ``frog-bt run`` builds it (site, tree, clock, :class:`Executive`, the
observers of ``--record`` / ``--rerun``), with no status line and no checkpoint.
It prints ``{"event": "tour", ...}`` with its memory each time a tour ends, answers
``stats`` on stdin with counters and memory, and stops on ``quit`` or when stdin
closes, printing ``{"event": "exit", ...}``.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import logging
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import memory_kb


def children_rss_kb() -> int:
    """RSS of this process's children (the telemetry writer), summed."""
    import multiprocessing

    return sum(memory_kb(c.pid).get("rss_kb", 0) for c in multiprocessing.active_children())


def say(event: str, **fields: Any) -> None:
    sys.stdout.write(json.dumps({"event": event, "t": time.monotonic(), **fields}) + "\n")
    sys.stdout.flush()


async def serve(args: argparse.Namespace) -> None:
    from frog_bt.behaviours import load_tree
    from frog_bt.clock import SimClock, WallClock
    from frog_bt.commands.run import attach_observers
    from frog_bt.config import load_site, parse_hostport
    from frog_bt.frontend.link import FrontendLink
    from frog_bt.rosbridge.client import RosbridgeClient
    from frog_bt.runtime.executive import Executive
    from frog_bt.runtime.exits import ExitRules
    from frog_bt.runtime.memory import pin_malloc_thresholds

    pin_malloc_thresholds()  # as frog-bt run does
    site = load_site(args.config)
    tree = load_tree(site=site)
    clock = SimClock() if args.sim_time else WallClock()
    client = RosbridgeClient(args.rosbridge)
    link = FrontendLink(parse_hostport(args.listen), parse_hostport(args.frontend), clock)
    executive = Executive(site, tree, clock, client, link, sim_time=args.sim_time)
    rules = ExitRules()
    executive.observers.attach(executive, [rules])
    observers = attach_observers(executive, record=args.record, rerun=args.rerun)
    tours = 0
    plain_tick = executive.tick

    def tick() -> None:
        nonlocal tours
        plain_tick()
        if rules.tours != tours:
            tours = rules.tours
            say(
                "tour",
                tours=tours,
                ticks=executive.core.ticks,
                **memory_kb(),
                child_rss_kb=children_rss_kb(),
            )

    executive.tick = tick  # type: ignore[method-assign]

    def stats() -> dict[str, Any]:
        client = executive.client.stats
        return {
            "received": client.received,
            "malformed": client.malformed,
            "ticks": executive.core.ticks,
            "tours": tours,
            "connected": executive.client.link.connected,
            **memory_kb(),
        }

    loop = asyncio.get_running_loop()
    reader = asyncio.StreamReader()
    await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)

    async def commands() -> None:
        async for line in reader:
            word = line.decode().strip()
            if word == "stats":
                say("stats", **stats())
            elif word == "quit":
                break
        executive.stop("told to stop")

    control = asyncio.create_task(commands())
    try:
        await executive.run()
    finally:
        control.cancel()
        for observer in observers:
            observer.close()
    say("exit", **stats())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--config", type=Path)
    p.add_argument("--rosbridge", required=True)
    p.add_argument("--frontend", required=True)
    p.add_argument("--listen", required=True)
    p.add_argument("--sim-time", action="store_true")
    p.add_argument("--record", type=Path)
    p.add_argument("--rerun")
    args = p.parse_args()
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    asyncio.run(serve(args))


if __name__ == "__main__":
    main()
