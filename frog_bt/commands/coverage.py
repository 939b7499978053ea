"""Which nodes of the tree recorded tours ran, and with which outcomes.

Each recording is replayed on the tree (the recordings' tick channel has the root's
status per tick, not each node's; a replay ticks exactly where the executive did), and
every node's runs and outcomes are counted over all of them. Printed as the tree, one
line per node, with the nodes the recordings never ran marked; `-o FILE.html` writes the
same as a self-contained page. Exit 0, or 2 when no recording could be read.

Examples:

  frog-bt coverage recordings/
  frog-bt coverage recordings/ -o coverage.html --tree trees/tour.yaml
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from frog_bt.commands.options import tree_argument, writable_file
from frog_bt.errors import DefinitionError, UsageError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("paths", nargs="+", type=Path, metavar="FILE_OR_DIR", help="recordings")
    p.add_argument("--tree", dest="tree_option", type=Path, metavar="FILE", help="tree file")
    p.add_argument("--config", type=Path, metavar="FILE", help="site configuration")
    p.add_argument("-o", "--output", type=Path, metavar="FILE.html", help="write a page")
    p.set_defaults(tree=None)


def run(args: argparse.Namespace) -> int:
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.offline.corpus import recordings
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import ReplayError
    from frog_bt.verify.coverage import Counter, NodeCount, lines, never_run, page
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
    model = compile_tree(tree, site)
    counts = [NodeCount() for _ in model.nodes]
    read = 0
    for path in recordings(args.paths):
        try:
            replay = Replay(path, site, load_tree(tree_path, site))  # a fresh tree each
        except (ReplayError, OSError) as exc:
            print(f"frog-bt: {path}: {exc}", file=sys.stderr)
            continue
        counter = Counter(counts)
        replay.observers.attach(replay, [counter])
        replay.run()
        read += 1
    if not read:
        print("frog-bt: no recording could be read", file=sys.stderr)
        return 2
    print("\n".join(lines(model, counts)))
    never = len(never_run(counts))
    print(
        f"{read} recordings: {len(model.nodes) - never} of {len(model.nodes)} nodes ran, "
        f"{never} never ran"
    )
    if args.output is not None:
        args.output.write_text(page(tree, model, counts, read), encoding="utf-8")
        print(f"wrote {args.output}")
    return 0
