"""Which nodes of the tree recorded tours ran, and with which outcomes.

Each recording is replayed on the tree (the recordings' tick channel has the root's
status per tick, not each node's; a replay ticks exactly where the executive did), and
every node's runs and outcomes are counted over all of them. Printed as the tree, one
line per node (how often it ran, and how each run ended: succeeded, failed, stopped
while running, or still running when its recording ended; a key under the tree says
what each means), with the nodes the recordings never ran marked, then one line of the tours
they hold (stops reached, played, skipped: counted as `frog-bt report` counts them);
`-o FILE.html` writes the tree as a self-contained page. `--jobs N` replays N files at a
time (processes), `--scheduler ADDRESS` on a dask.distributed cluster: the same Executor
seam as `frog-bt report`. Exit 0, or 2 when no recording could be read.

Examples:

  frog-bt coverage recordings/
  frog-bt coverage recordings/ -o coverage.html --tree trees/tour.yaml
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from collections import Counter
from pathlib import Path
from typing import Any

from frog_bt.commands.options import tree_argument, writable_file
from frog_bt.errors import DefinitionError, UsageError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="+", type=Path, metavar="FILE_OR_DIR", help="recordings")
    p.add_argument("--tree", dest="tree_option", type=Path, metavar="FILE", help="tree file")
    p.add_argument("--config", type=Path, metavar="FILE", help="site configuration")
    p.add_argument("-o", "--output", type=Path, metavar="FILE.html", help="write a page")
    p.add_argument("--jobs", type=int, default=1, metavar="N", help="replay N files at a time")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="replay on this dask.distributed scheduler (tcp://HOST:PORT) instead",
    )
    p.set_defaults(tree=None)


def run(args: argparse.Namespace) -> int:
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.offline.corpus import recordings
    from frog_bt.offline.executors import ExecutorError, executor
    from frog_bt.verify.coverage import KEY, NodeCount, add, lines, never_run, page
    from frog_bt.verify.model import compile_tree

    try:
        if args.output is not None:
            writable_file(args.output, "-o")
        site = load_site(args.config)
        tree_path = tree_argument(args)
        tree = load_tree(tree_path, site)
    except (UsageError, DefinitionError) as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    model = compile_tree(tree)
    counts = [NodeCount() for _ in model.nodes]
    tours: Counter[str] = Counter()
    read = 0
    files = list(recordings(args.paths))
    try:
        with executor(max(1, args.jobs), args.scheduler) as pool:
            done = pool.map(count_file, files, [tree_path] * len(files), [args.config] * len(files))
            for path, got, told in done:
                if isinstance(got, str):
                    print(f"frog-bt: {path}: {got}", file=sys.stderr)
                    continue
                add(counts, got)
                tours.update(told)
                read += 1
    except ExecutorError as exc:
        print(f"frog-bt coverage: {exc}", file=sys.stderr)
        return 2
    if not read:
        print("frog-bt: no recording could be read", file=sys.stderr)
        return 2
    print("\n".join(lines(model, counts)))
    print(textwrap.fill(KEY, 88))
    print(
        f"tours: {tours['tours']} ({tours['ended']} ended, {tours['aborted']} aborted); "
        f"stops reached {tours['reached']}, played {tours['played']}, "
        f"skipped {tours['skipped']}"
    )
    never = len(never_run(counts))
    print(
        f"{read} recordings: {len(model.nodes) - never} of {len(model.nodes)} nodes ran, "
        f"{never} never ran"
    )
    if args.output is not None:
        args.output.write_text(page(tree, model, counts, read), encoding="utf-8")
        print(f"wrote {args.output}")
    return 0


def count_file(
    path: Path, tree_file: Path | None, config: Path | None
) -> tuple[str, list[Any] | str, dict[str, int]]:
    """One recording's counts, replayed in a worker (``--jobs``, ``--scheduler``): the
    site and the tree are loaded there, so only paths cross to it; the counts, or why the
    file could not be read, and its tours (:func:`tour_counts`)."""
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.model.ledger import TourLedger
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import ReplayError
    from frog_bt.verify.coverage import Counter, NodeCount
    from frog_bt.verify.model import preorder

    site = load_site(config)
    tree = load_tree(tree_file, site)
    counts = [NodeCount() for _ in preorder(tree.root)]
    try:
        replay = Replay(path, site, tree)
    except (ReplayError, OSError) as exc:
        return str(path), str(exc), {}
    ledger = TourLedger(site.tour_plan())
    replay.observers.attach(replay, [Counter(counts), ledger])
    replay.run()
    return str(path), counts, tour_counts(ledger)


def tour_counts(ledger: Any) -> dict[str, int]:
    """A replay's tours, as the one count of tours has them: how many, how they ended,
    and their stops reached, played and skipped (the report's ``stops_skipped``)."""
    order = ledger.plan.content
    tours = ledger.tours
    return {
        "tours": len(tours),
        "ended": ledger.completed,
        "aborted": ledger.aborted,
        "reached": sum(len([p for p in r.reached if p in order]) for r in tours),
        "played": sum(len([p for p in r.played if p in order]) for r in tours),
        "skipped": sum(len(r.skips(order)) for r in tours),
    }
