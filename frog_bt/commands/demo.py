"""Run the simulator and the executive together for one full tour on sim time.

Starts the built-in simulator (frog-bt sim) on free loopback ports, runs the
executive against it with --sim-time --once, and prints a summary: the route
with the time-of-day variants chosen, the content played, the visitors
recruited, what went wrong (stops skipped and why, navigation retries, failed
approaches, content timeouts, front-end restarts, aborts), and how much
simulated and wall time the tour took. Exits 0 only when the tour ended docked
with every stop visited.

With --console the tour runs at a speed a person can follow (2x unless --speed says
otherwise), and the executive runs on, as on a robot, until Ctrl-C (SIGINT or SIGTERM):
a request for help holds until someone answers it on the page, and "done by hand" is
done in the simulator first, as a person would (the robot put on its charger, or off
it, its fault fixed). The summary is printed when the first tour is over. The default
--timeout grows as the speed falls: 300 wall seconds at the default 50x, the same
simulated time at any other speed.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import signal
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from frog_bt.behaviours import load_tree
from frog_bt.commands.console_options import (
    add_console_arguments,
    console_settings,
    start_people,
)
from frog_bt.commands.options import add_tree_and_config
from frog_bt.config import Site, load_site
from frog_bt.errors import DefinitionError, UsageError, error_lines
from frog_bt.tree.loader import LoadedTree

if TYPE_CHECKING:
    from frog_bt.live.console.server import Console
    from frog_bt.live.summary import TourSummary
    from frog_bt.rehearsal import Rehearsal
    from frog_bt.runtime.executive import Outcome
    from frog_bt.sim.scenario import Scenario

CONSOLE_SPEED = 2.0  # with --console: slow enough to follow on the page
TIMEOUT = 300.0  # wall seconds at REFERENCE_SPEED; the same simulated time at any speed
REFERENCE_SPEED = 50.0


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--scenario",
        default="default",
        metavar="NAME|FILE",
        help="simulator scenario (default: default)",
    )
    p.add_argument(
        "--speed",
        type=float,
        help=f"sim-time speed factor (default: the scenario's; with --console {CONSOLE_SPEED:g})",
    )
    add_tree_and_config(p)
    p.add_argument(
        "--timeout",
        type=float,
        help=f"give up after this many wall seconds (default: {TIMEOUT:g} at "
        f"{REFERENCE_SPEED:g}x, longer when slower)",
    )
    p.add_argument(
        "--record",
        type=Path,
        default=Path("frog-demo.mcap"),
        metavar="FILE.mcap",
        help="MCAP recording of the tour (default: frog-demo.mcap)",
    )
    p.add_argument(
        "--rerun",
        default="save:frog-demo.rrd",
        metavar="SPEC",
        help="rerun telemetry: spawn | save:FILE.rrd | connect:URL | serve | off "
        "(default: save:frog-demo.rrd)",
    )
    add_console_arguments(p)
    p.add_argument("--quiet", action="store_true", help="no live status line")


def run(args: argparse.Namespace) -> int:
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    from frog_bt.sim import load_scenario

    try:
        site = load_site(args.config)
        tree = load_tree(args.tree, site)
        scenario = load_scenario(args.scenario)
        console_settings(args)
        if args.record:  # checked before anything starts: one line, not a traceback
            from frog_bt.commands.run import record_target

            args.record = record_target(Path(args.record))
    except (DefinitionError, UsageError) as exc:
        for line in error_lines(exc):
            print(f"frog-bt: {line}", file=sys.stderr)
        return 2
    speed, args.timeout = pace(args.speed, args.timeout, scenario.speed, bool(args.console))
    scenario = scenario.model_copy(update={"speed": speed})
    return asyncio.run(_demo(site, tree, scenario, args))


def pace(
    speed: float | None, timeout: float | None, scenario_speed: float, console: bool
) -> tuple[float, float]:
    """The speed (``--speed``, else 2x with a console, else the scenario's) and the wall
    timeout (``--timeout``, else long enough for what 300 s give at 50x)."""
    chosen = speed or (CONSOLE_SPEED if console else scenario_speed)
    return chosen, timeout or max(TIMEOUT, TIMEOUT * REFERENCE_SPEED / chosen)


async def _demo(site: Site, tree: LoadedTree, scenario: Scenario, args: argparse.Namespace) -> int:
    from frog_bt.commands.run import attach_observers
    from frog_bt.live.summary import TourSummary
    from frog_bt.rehearsal import Rehearsal
    from frog_bt.runtime.executive import Executive
    from frog_bt.runtime.observer import Observer, attach_all, close_all
    from frog_bt.runtime.status import StatusLine

    summary = TourSummary(site)
    status = None if args.quiet else StatusLine()
    rerun = None if args.rerun == "off" else args.rerun
    observers: list[Observer] = []

    def prepare(executive: Executive) -> None:
        observers.extend(attach_all(executive, [summary, *([status] if status else [])]))
        observers.extend(attach_observers(executive, record=args.record, rerun=rerun))

    wall0 = time.monotonic()
    # With a console the executive goes on after its tour, as on a robot: a request for
    # help holds until a person answers it on the page (or Ctrl-C), and "done by hand"
    # is done in the simulator first, as a person would (Rehearsal.lend_hands).
    held = bool(args.console)
    rehearsal = Rehearsal(scenario, site=site, tree=tree, prepare=prepare, once=not held)
    sim0 = rehearsal.sim.clock.now()
    people = None
    try:
        async with rehearsal:
            try:
                people = await start_people(rehearsal.executive, console_settings(args), observers)
            except UsageError as exc:
                print(f"frog-bt: {exc}", file=sys.stderr)
                rehearsal.executive.stop(str(exc), 2)
                return 2
            if held and people.console is not None:
                rehearsal.lend_hands()
                return await _held(args, scenario, summary, rehearsal, people.console, wall0, sim0)
            timed_out = False
            try:
                outcome = await rehearsal.finish(args.timeout)
            except TimeoutError:
                timed_out = True
        outcome = rehearsal.executive.outcome
        if timed_out:  # said after the executive stopped (stopping says "no tour ended")
            outcome.code, outcome.reason = 1, _too_slow(args.timeout, scenario.speed)
        close_all(observers)
        observers.clear()
        return _report(args, scenario, summary, rehearsal, outcome, wall0, sim0, rerun)
    finally:
        if people is not None:
            await people.close()
        close_all(observers)


def _too_slow(timeout: float, speed: float) -> str:
    return (
        f"no docked finish within {timeout:g} s of wall time "
        f"(--timeout {timeout:g} at --speed {speed:g}): give a longer --timeout"
    )


async def _held(
    args: argparse.Namespace,
    scenario: Scenario,
    summary: TourSummary,
    rehearsal: Rehearsal,
    console: Console,
    wall0: float,
    sim0: float,
) -> int:
    """With a console: the executive runs until SIGINT or SIGTERM, whatever happens. The
    summary is printed when the first tour is over (or after ``--timeout``); the exit
    code is the summary's."""
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    try:
        print(
            f"frog-bt demo: the console is at http://{console.host}:{console.bound_port}/ "
            "(Ctrl-C to end)",
            flush=True,
        )
        over = asyncio.create_task(_first_tour_over(summary))
        stopped = asyncio.create_task(stop.wait())
        await asyncio.wait({over, stopped}, timeout=args.timeout, return_when="FIRST_COMPLETED")
        over.cancel()
        outcome = rehearsal.executive.outcome
        if not summary.tours and not stop.is_set():
            outcome.code, outcome.reason = 1, _too_slow(args.timeout, scenario.speed)
        rerun = None if args.rerun == "off" else args.rerun
        code = _report(args, scenario, summary, rehearsal, outcome, wall0, sim0, rerun)
        if not stop.is_set():
            print(
                f"frog-bt demo: the console stays open at http://{console.host}:"
                f"{console.bound_port}/ and the robot goes on (Ctrl-C to end)",
                flush=True,
            )
        await stopped
        return code
    finally:
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.remove_signal_handler(sig)


async def _first_tour_over(summary: TourSummary) -> None:
    """Returns once the first tour has ended or was aborted (the summary heard it)."""
    while not summary.tours:
        await asyncio.sleep(FIRST_TOUR_POLL)


FIRST_TOUR_POLL = 0.2  # wall seconds between looks at the summary


def _report(
    args: argparse.Namespace,
    scenario: Scenario,
    summary: TourSummary,
    rehearsal: Rehearsal,
    outcome: Outcome,
    wall0: float,
    sim0: float,
    rerun: str | None,
) -> int:
    """Print the tour's summary; the exit code."""
    clock = rehearsal.executive.clock
    wall, simulated = time.monotonic() - wall0, rehearsal.sim.clock.now() - sim0
    print(
        f"frog-bt demo: scenario {args.scenario!r}, started "
        f"{scenario.start_time.astimezone(clock.tz):%Y-%m-%d %H:%M} local time"
    )
    for line in summary.lines(rehearsal.executive.link.stats):
        print("  " + line)
    print(
        f"  time:      {simulated / 60:.1f} min simulated in {wall:.1f} s "
        f"({simulated / max(wall, 1e-9):.0f}x real time)"
    )
    if outcome.code:
        print(f"frog-bt: {outcome.reason}", file=sys.stderr)
        return outcome.code
    if not summary.complete:
        print(f"frog-bt: {summary.verdict()}", file=sys.stderr)
        return 1
    if args.record:
        print(f"  recording: {args.record}  (replay: frog-bt replay {args.record})")
    if rerun and rerun.startswith("save:"):
        print(f"  telemetry: {rerun[5:]}  (view: rerun {rerun[5:]})")
    return 0
