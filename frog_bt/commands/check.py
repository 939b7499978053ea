"""Check a tour tree and the site configuration, and draw nothing.

Loads the site configuration and the tree as `frog-bt run` does (includes,
foreach, parameters, the order-aware data-flow check) and reports every error
found, one line each: `FILE:LINE:COLUMN: PATH: what was expected`, sorted by
file and line. Exit 0 when both are valid, 2 otherwise. No robot, no network:
fast enough for an editor's save hook.

Examples:

  frog-bt check                                  the packaged tour and site
  frog-bt check trees/tour.yaml --config config/site.yaml
"""

from __future__ import annotations

import argparse
import sys

from frog_bt.commands.options import add_tree_argument, load_tree_argument
from frog_bt.config import DEFAULT_CONFIG
from frog_bt.errors import DefinitionError, TreeErrors, UsageError


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_argument(p)


def run(args: argparse.Namespace) -> int:
    try:
        _, _, tree = load_tree_argument(args)
    except UsageError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    except TreeErrors as exc:
        for error in exc.errors:
            print(error, file=sys.stderr)
        print(f"frog-bt: {len(exc.errors)} errors", file=sys.stderr)
        return 2
    except DefinitionError as exc:
        print(exc, file=sys.stderr)
        return 2
    nodes = sum(1 for _ in tree.nodes())
    print(f"ok: {tree.file} ({nodes} nodes), {args.config or DEFAULT_CONFIG}")
    return 0
