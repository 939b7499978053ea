"""Run the simulator and the executive together for one full tour on sim time.

Starts the built-in simulator (frog-bt sim) on free loopback ports, runs the
executive against it with --sim-time --once, and prints a summary: the route
with the time-of-day variants chosen, the content played, the visitors
recruited, and how much simulated and wall time the tour took.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import socket
import sys
import time
from pathlib import Path

from frog_bt.config import load_site
from frog_bt.errors import DefinitionError
from frog_bt.tree.loader import load_tree


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scenario", default="default", metavar="NAME|FILE",
                   help="simulator scenario (default: default)")
    p.add_argument("--speed", type=float, help="sim-time speed factor (default: the scenario's)")
    p.add_argument("--config", type=Path, help="site configuration (default: config/site.yaml)")
    p.add_argument("--tree", type=Path, help="tour tree (default: trees/tour.yaml)")
    p.add_argument("--timeout", type=float, default=300.0,
                   help="give up after this many wall seconds (default: 300)")
    p.add_argument("--record", type=Path, default=Path("frog-demo.mcap"), metavar="FILE.mcap",
                   help="MCAP recording of the tour (default: frog-demo.mcap)")
    p.add_argument("--rerun", default="save:frog-demo.rrd", metavar="SPEC",
                   help="rerun telemetry: spawn | save:FILE.rrd | connect:URL | serve | off "
                   "(default: save:frog-demo.rrd)")
    p.add_argument("--quiet", action="store_true", help="no live status line")


def free_udp_port(host: str = "127.0.0.1") -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def run(args: argparse.Namespace) -> int:
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    from frog_bt.sim import load_scenario

    try:
        site = load_site(args.config)
        tree = load_tree(args.tree, site)
        scenario = load_scenario(args.scenario)
    except DefinitionError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    if args.speed:
        scenario = scenario.model_copy(update={"speed": args.speed})
    return asyncio.run(_demo(site, tree, scenario, args))


async def _demo(site, tree, scenario, args) -> int:  # type: ignore[no-untyped-def]
    from frog_bt.clock import SimClock
    from frog_bt.commands.run import attach_observers
    from frog_bt.executive import Executive
    from frog_bt.sim import Simulator
    from frog_bt.status import StatusLine
    from frog_bt.summary import TourSummary

    listen = ("127.0.0.1", free_udp_port())
    sim = Simulator(scenario, rosbridge_port=0, frontend_port=0, executive=listen)
    await sim.start()
    clock = SimClock()
    executive = Executive(site, tree, clock,
                          rosbridge_url=f"ws://127.0.0.1:{sim.rosbridge_port}",
                          frontend=("127.0.0.1", sim.frontend_port), listen=listen,
                          sim_time=True, once=True)
    summary = TourSummary(site)
    summary.attach(executive.taps)
    status = None if args.quiet else StatusLine()
    if status is not None:
        executive.taps.tick.append(status.update)
    rerun = None if args.rerun == "off" else args.rerun
    observers = attach_observers(executive, record=args.record, rerun=rerun)
    wall0, sim0 = time.monotonic(), sim.clock.now()
    loop = asyncio.get_running_loop()
    loop.call_later(args.timeout, executive.stop, f"no docked finish within {args.timeout:g} s "
                    "of wall time", 1)
    try:
        outcome = await executive.run()
    finally:
        await sim.stop()
        for observer in observers:
            observer.close()
        if status is not None:
            status.close()
    wall, simulated = time.monotonic() - wall0, sim.clock.now() - sim0
    print(f"frog-bt demo: scenario {args.scenario!r}, started "
          f"{clock.local_time().strftime('%Y-%m-%d') if clock.ready else '-'} "
          f"{scenario.start_time.astimezone(clock.tz):%H:%M} local time")
    for line in summary.lines():
        print("  " + line)
    print(f"  time:      {simulated / 60:.1f} min simulated in {wall:.1f} s "
          f"({simulated / max(wall, 1e-9):.0f}x real time)")
    if outcome.code:
        print(f"frog-bt: {outcome.reason}", file=sys.stderr)
        return outcome.code
    print(f"  outcome:   {outcome.reason}")
    if args.record:
        print(f"  recording: {args.record}  (replay: frog-bt replay {args.record})")
    if rerun and rerun.startswith("save:"):
        print(f"  telemetry: {rerun[5:]}  (view: rerun {rerun[5:]})")
    return 0
