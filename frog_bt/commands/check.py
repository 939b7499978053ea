"""Check a tour tree and the site configuration, and draw nothing.

Loads the site configuration and the tree as `frog-bt run` does (includes,
foreach, parameters, the order-aware data-flow check) and reports every error
found, one line each: `FILE:LINE:COLUMN: PATH: what was expected`, sorted by
file and line. Then, when it is fast enough (a bounded number of states), it proves
the tree as `frog-bt verify` does and lists each property that does not hold
(`--no-verify` skips that), each at the node it concerns, `FILE:LINE:COLUMN: PATH:
PROPERTY: what`, with its shortest run on the lines after, and each that holds only
vacuously (no run reaches its trigger). Exit 0 when both are valid and every property
holds, 2 otherwise. No robot, no network; the proof ticks the real tree through every
run (about a minute for the shipped tour on 2 cores): `--no-verify` for an editor's save hook.

Examples:

  frog-bt check                                  the packaged tour and site
  frog-bt check trees/tour.yaml --config config/site.yaml
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from frog_bt import resources
from frog_bt.commands.exposed import exposed
from frog_bt.commands.options import add_tree_argument, load_tree_argument
from frog_bt.config import DEFAULT_CONFIG
from frog_bt.errors import DefinitionError, TreeErrors, UsageError

VERIFY_STATES = 200_000  # beyond this, check leaves the proof to `frog-bt verify`


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_argument(p)
    p.add_argument("--no-verify", action="store_true", help="do not prove the tree's properties")


def run(args: argparse.Namespace) -> int:
    try:
        _, site, tree = load_tree_argument(args)
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
    config = Path(args.config) if args.config else resources.site_dir() / resources.SITE_FILE
    for line in exposed(config, site):
        print(f"frog-bt: warning: {line}", file=sys.stderr)
    nodes = sum(1 for _ in tree.nodes())
    proved = ""
    if not args.no_verify:
        from frog_bt.verify.explore import TooBig
        from frog_bt.verify.prove import prove
        from frog_bt.verify.report import finding, vacuous_finding

        try:
            verdict = prove(tree, site, limit=VERIFY_STATES)
        except TreeErrors as exc:
            for error in exc.errors:
                print(error, file=sys.stderr)
            return 2
        except DefinitionError as exc:
            print(exc, file=sys.stderr)
            return 2
        except TooBig:
            proved = "; not proved (too many states: run frog-bt verify)"
        else:
            for broken in verdict.broken:
                print("\n".join(finding(verdict.model, broken)), file=sys.stderr)
            for name in verdict.vacuous:
                print(vacuous_finding(verdict, name), file=sys.stderr)
            if not verdict.ok:
                return 2
            proved = f"; {len(verdict.checked)} properties hold"
    print(f"ok: {tree.file} ({nodes} nodes), {args.config or DEFAULT_CONFIG}{proved}")
    return 0
