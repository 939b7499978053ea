"""Re-run the tour tree offline on a recording's inputs, on the recording's clock.

Reads an MCAP file written by `frog-bt run --record` (or `frog-bt demo`), feeds
the recorded robot messages and front-end events to the tree as fast as it can,
and compares the commands it sends with the recorded ones. Prints "identical"
and exits 0 when they match; otherwise prints the first divergence (time,
expected, got) and exits 1. Exit 2: not a file, not MCAP, channels missing, or
a bad tree or configuration.

What if: give a changed tree or configuration to see where it would have acted
differently on the same inputs:

  frog-bt replay frog-demo.mcap
  frog-bt replay frog-demo.mcap --tree my-trees/tour.yaml
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from frog_bt.commands.options import add_tree_and_config
from frog_bt.config import load_site
from frog_bt.errors import DefinitionError
from frog_bt.tree.loader import load_tree

REDRAW = 0.1  # wall seconds between progress-bar redraws
BAR = 30


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", type=Path, metavar="FILE.mcap", help="recording to replay")
    add_tree_and_config(p)
    p.add_argument("--rerun", metavar="SPEC",
                   help="rerun telemetry of the replay: spawn | save:FILE.rrd | connect:URL | "
                   "serve (default: off)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


class Progress:
    """A one-line progress bar on a terminal: percent of the recording's time covered."""

    def __init__(self, start: float, end: float, out: TextIO,
                 wall: Callable[[], float] = time.monotonic) -> None:
        self.start, self.span = start, max(end - start, 1e-9)
        self.out = out
        self._wall = wall
        self._drawn: float | None = None
        self._shown = False

    def __call__(self, t: float) -> None:
        now = self._wall()
        if self._drawn is not None and now - self._drawn < REDRAW:
            return
        self._drawn = now
        frac = min(max((t - self.start) / self.span, 0.0), 1.0)
        filled = round(frac * BAR)
        self.out.write(f"\rreplay [{'#' * filled}{'-' * (BAR - filled)}] {frac:4.0%} "
                       f"{t - self.start:7.1f}/{self.span:.1f} s")
        self.out.flush()
        self._shown = True

    def close(self) -> None:
        if self._shown:
            self.out.write("\r\033[K")
            self.out.flush()


def run(args: argparse.Namespace) -> int:
    from frog_bt.tools.replay import Replay, ReplayError, differences, local_time

    try:
        site = load_site(args.config)
        tree = load_tree(args.tree, site)
        replay = Replay(args.file, site, tree)
    except (DefinitionError, ReplayError, ValueError) as exc:
        print(f"frog-bt replay: {exc}", file=sys.stderr)
        return 2
    telemetry: Any = None
    if args.rerun:
        from frog_bt.telemetry import Telemetry

        try:
            telemetry = Telemetry.open(args.rerun, site, tree)
        except (ValueError, OSError) as exc:
            replay.close()
            print(f"frog-bt replay: {exc}", file=sys.stderr)
            return 2
        telemetry.attach(replay.core)
    progress = None
    if not args.quiet and sys.stderr.isatty():
        progress = Progress(replay.start, replay.end, sys.stderr)
    try:
        result = replay.run(progress)
    finally:
        if progress is not None:
            progress.close()
        if telemetry is not None:
            telemetry.close()
    commands = f"{result.ros_commands} ROS and {result.frontend_commands} front-end commands"
    if not result.exact:
        print("note: the recording has no /frog_bt/tick channel; ticks follow the live rules")
    div = result.divergence
    if div is None:
        print(f"identical: {commands}")
    else:
        print(f"divergence at {local_time(div.t)} (+{div.t - result.start:.1f} s into the "
              f"recording), command {div.number}:")
        for label, command in (("expected", div.expected), ("got", div.got)):
            text = "nothing" if command is None else (
                f"{command}  (at +{command.t - result.start:.1f} s)")
            print(f"  {label + ':':9} {text}")
        print(f"  {'differs:':9} {differences(div.expected, div.got, site)}")
        for label, command in (("recorded", div.expected), ("replayed", div.got)):
            if command is not None:
                print(f"  {label + ':':9} sent by {command.node or '? (no blame recorded)'}")
    simulated = result.covered - result.start
    wall = result.wall
    print(f"replayed {simulated:.1f} of {result.end - result.start:.1f} s recorded in "
          f"{wall:.2f} s wall ({simulated / max(wall, 1e-9):.0f}x real time): "
          f"{result.inputs} inputs, {result.ticks} ticks, {commands}")
    return 0 if div is None else 1
