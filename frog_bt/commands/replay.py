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

Batch what-if over a corpus (several files, or directories of *.mcap): one line
per tour (identical, diverged with its first divergence, or unreadable and
skipped), then a summary grouping the divergences by node and what differs;
--jobs N replays N files at a time (processes), --scheduler ADDRESS on a
dask.distributed cluster instead, --report FILE writes it as JSON.
Exit 0 only when every tour replays identically.

  frog-bt replay recordings/ --config what-if/site.yaml --jobs 2 --report out.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from frog_bt.behaviours import load_tree
from frog_bt.commands.options import add_tree_and_config
from frog_bt.config import load_site
from frog_bt.errors import DefinitionError, error_lines
from frog_bt.runtime.observer import attach_all

REDRAW = 0.1  # wall seconds between progress-bar redraws
BAR = 30


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "files",
        type=Path,
        nargs="+",
        metavar="FILE_OR_DIR",
        help="recording(s) to replay: MCAP files, or directories of them",
    )
    add_tree_and_config(p)
    p.add_argument(
        "--rerun",
        metavar="SPEC",
        help="rerun telemetry of the replay: spawn | save:FILE.rrd | connect:URL | "
        "serve (default: off)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--format",
        choices=("text", "json"),
        default="text",
        help="one recording's report: text for people, json for scripts",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="corpus: recordings replayed at a time, in processes (default 1)",
    )
    p.add_argument(
        "--report",
        type=Path,
        metavar="FILE.json",
        help="corpus: write every tour's row and the summary as JSON",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="corpus: run on this dask.distributed scheduler (tcp://HOST:PORT) "
        "instead of local processes (pip install 'frog-bt[fleet]')",
    )


class Progress:
    """A one-line progress bar on a terminal: percent of the recording's time covered."""

    def __init__(
        self, start: float, end: float, out: TextIO, wall: Callable[[], float] = time.monotonic
    ) -> None:
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
        self.out.write(
            f"\rreplay [{'#' * filled}{'-' * (BAR - filled)}] {frac:4.0%} "
            f"{t - self.start:7.1f}/{self.span:.1f} s"
        )
        self.out.flush()
        self._shown = True

    def close(self) -> None:
        if self._shown:
            self.out.write("\r\033[K")
            self.out.flush()


def run(args: argparse.Namespace) -> int:
    if (
        len(args.files) > 1
        or args.files[0].is_dir()
        or args.report
        or args.jobs != 1
        or args.scheduler
    ):
        return run_corpus(args)
    args.file = args.files[0]
    return run_one(args)


def run_corpus(args: argparse.Namespace) -> int:
    from frog_bt.offline import replay as _replay  # noqa: F401 - imported once, before the fork
    from frog_bt.offline.corpus import recordings, replay_corpus, summary, summary_line
    from frog_bt.offline.executors import ExecutorError, executor

    if args.rerun:
        print("frog-bt replay: --rerun takes one recording", file=sys.stderr)
        return 2
    if args.jobs < 1:
        print(f"frog-bt replay: --jobs {args.jobs}: expected 1 or more", file=sys.stderr)
        return 2
    try:
        site = load_site(args.config)  # checked once, up front
        load_tree(args.tree, site)
    except DefinitionError as exc:
        for line in error_lines(exc):
            print(f"frog-bt replay: {line}", file=sys.stderr)
        return 2
    files = recordings(args.files)
    if not files:
        print("frog-bt replay: no recordings (*.mcap) found", file=sys.stderr)
        return 2
    bar = None if args.quiet or not sys.stderr.isatty() else CountBar(sys.stderr)
    # Processes (forked: workers start with the modules imported), or a dask cluster;
    # the site goes with each task.
    rows = []
    try:
        with executor(args.jobs, args.scheduler) as pool:
            for row in replay_corpus(files, args.tree, site, pool, bar):
                rows.append(row)
                if bar is not None:
                    bar.clear()
                print(row.line(), flush=True)
    except ExecutorError as exc:
        print(f"frog-bt replay: {exc}", file=sys.stderr)
        return 2
    if bar is not None:
        bar.clear()
    totals = summary(rows)
    print(summary_line(totals))
    if args.report is not None:
        args.report.write_text(
            json.dumps({"tours": [r.as_dict() for r in rows], "summary": totals}, indent=1) + "\n"
        )
    return 0 if totals["identical"] == totals["tours"] else 1


def report(result: Any, site: Any) -> dict[str, Any]:
    """One replay as JSON: identical or the first divergence, in domain terms."""
    from frog_bt.recordings.commands import differences, what_differs

    div = result.divergence
    out: dict[str, Any] = {
        "identical": div is None,
        "start": result.start,
        "end": result.end,
        "inputs": result.inputs,
        "ticks": result.ticks,
        "ros_commands": result.ros_commands,
        "frontend_commands": result.frontend_commands,
        "exact_ticks": result.exact,
        "recovered": result.recovered,
        "operator_commands": result.operator_commands,
        "alerts": result.alerts,
        "bad_messages": result.bad_count,
        "bad": result.bad,
    }
    if div is not None:

        def side(command: Any) -> dict[str, Any] | None:
            if command is None:
                return None
            return {
                "at": command.t - result.start,
                "channel": command.channel,
                "payload": command.payload,
                "node": command.node,
                "reads": command.reads,
            }

        out["divergence"] = {
            "number": div.number,
            "at": div.t - result.start,
            "differs": differences(div.expected, div.got, site),
            "story": div.story,
            "what": what_differs(div.expected, div.got, site),
            "recorded": side(div.expected),
            "replayed": side(div.got),
            "doubted": [{"side": side_, "why": why} for side_, why in div.doubts],
        }
    return out


class CountBar:
    """A one-line progress bar over the corpus, on a terminal."""

    def __init__(self, out: TextIO, label: str = "replay", unit: str = "tours") -> None:
        self.out = out
        self.label, self.unit = label, unit

    def __call__(self, done: int, total: int) -> None:
        filled = round(done / max(total, 1) * BAR)
        self.out.write(
            f"\r{self.label} [{'#' * filled}{'-' * (BAR - filled)}] {done}/{total} {self.unit}"
        )
        self.out.flush()

    def clear(self) -> None:
        self.out.write("\r\033[K")
        self.out.flush()


def run_one(args: argparse.Namespace) -> int:
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import ReplayError, differences, local_time

    try:
        site = load_site(args.config)
        tree = load_tree(args.tree, site)
        replay = Replay(args.file, site, tree)
    except (DefinitionError, ReplayError, ValueError) as exc:
        print(f"frog-bt replay: {exc}", file=sys.stderr)
        return 2
    telemetry: Any = None
    if args.rerun:
        from frog_bt.live.telemetry import Telemetry

        try:
            telemetry = Telemetry.open(args.rerun, site, tree)
        except (ValueError, OSError) as exc:
            print(f"frog-bt replay: {exc}", file=sys.stderr)
            return 2
        attach_all(replay, [telemetry])
        from frog_bt.commands.rerun_compare import compare_lanes

        compare_lanes(telemetry.rec, replay, site)
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
    if result.operator_commands:
        commands += f", {result.operator_commands} operator commands"
    if result.alerts:
        commands += f", {result.alerts} alert changes"
    if args.format == "json":
        print(json.dumps(report(result, site), indent=1))
        return 0 if result.divergence is None else 1
    if not result.exact:
        print("note: the recording has no /frog_bt/tick channel; ticks follow the live rules")
    for recovered in result.recovered:
        print(f"note: {recovered}; replayed up to the cut")
    if result.bad_count:
        print(f"note: {result.bad_count} bad message(s) in the recording, skipped:")
        for reason in result.bad:
            print(f"  {reason}")
    div = result.divergence
    if div is None:
        print(f"identical: {commands}")
    else:
        print(
            f"divergence at {local_time(div.t)} (+{div.t - result.start:.1f} s into the "
            f"recording), command {div.number}:"
        )
        for label, command in (("expected", div.expected), ("got", div.got)):
            text = (
                "nothing"
                if command is None
                else (f"{command}  (at +{command.t - result.start:.1f} s)")
            )
            print(f"  {label + ':':9} {text}")
        print(f"  {'differs:':9} {differences(div.expected, div.got, site)}")
        if div.story:  # an alert or an operator's answer, in domain terms
            print(f"  {'':9} {div.story}")
        for side, why in div.doubts:  # a robot answer one side believed and the other not
            where = "recording" if side == "recorded" else "replay"
            print(f"  {'doubted:':9} {why} (in the {where} only)")
        for label, command in (("recorded", div.expected), ("replayed", div.got)):
            if command is not None:
                print(f"  {label + ':':9} sent by {command.node or '? (no blame recorded)'}")
                for key, value in command.reads.items():  # what decided it
                    print(f"  {'':9}   {key} = {value}")
    simulated = result.covered - result.start
    wall = result.wall
    print(
        f"replayed {simulated:.1f} of {result.end - result.start:.1f} s recorded in "
        f"{wall:.2f} s wall ({simulated / max(wall, 1e-9):.0f}x real time): "
        f"{result.inputs} inputs, {result.ticks} ticks, {commands}"
    )
    return 0 if div is None else 1
