"""Prove a tour tree: explore every run of it under every outcome of its leaves.

Each leaf is replaced by its abstraction (the outcomes it may have per tick; a wait runs
for a bounded number of ticks), the guards' inputs (battery, faults, operator commands,
the front end's and visitors' answers) are chosen anew at every tick, and every state the
tree can reach is visited, breadth first. The built-in properties (ends-well,
home-obeyed, service-off-obeyed, pause-obeyed, no-content-while-driving,
bounded-retries, no-dead-reads) and the tree file's own `properties:` are checked.
Exit 0 when all hold; 1 with the shortest run that breaks each one that does not;
2 when the tree or the configuration is invalid.

Examples:

  frog-bt verify                                 the packaged tour and site
  frog-bt verify trees/tour.yaml --format mermaid
"""

from __future__ import annotations

import argparse
import sys

from frog_bt.commands.options import add_tree_argument, load_tree_argument
from frog_bt.errors import DefinitionError, TreeErrors, UsageError
from frog_bt.verify.explore import TooBig
from frog_bt.verify.prove import prove
from frog_bt.verify.report import broken_text, summary


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_argument(p)
    p.add_argument(
        "--format",
        choices=("mermaid", "dot"),
        help="draw the tree with the nodes of each broken run marked",
    )


def run(args: argparse.Namespace) -> int:
    try:
        _, site, tree = load_tree_argument(args)
        verdict = prove(tree, site)
    except UsageError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    except TreeErrors as exc:
        for error in exc.errors:
            print(error, file=sys.stderr)
        return 2
    except DefinitionError as exc:
        print(exc, file=sys.stderr)
        return 2
    except TooBig as exc:
        print(f"frog-bt: the tree is too big to verify whole: {exc}", file=sys.stderr)
        return 2
    if verdict.ok:
        print(summary(verdict))
        return 0
    print(broken_text(verdict, args.format))
    return 1
