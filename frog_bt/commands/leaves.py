"""List every node type a tree file can name: parameters, blackboard keys, what it does.

The catalogue comes from the code itself (the registered leaves and decorators,
and the composites), so it is always the one the installed `frog-bt` accepts.
`docs/TREES.md`'s node reference is this command's Markdown.

Examples:

  frog-bt leaves                     Markdown, for people
  frog-bt leaves --format json       for tools (an editor plug-in, a linter)
"""

from __future__ import annotations

import argparse
import sys

from frog_bt.behaviours import FACTORY
from frog_bt.tree.catalogue import as_json, as_markdown, catalogue


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--format",
        choices=("markdown", "json"),
        default="markdown",
        help="output format (default: markdown)",
    )


def run(args: argparse.Namespace) -> int:
    nodes = catalogue(FACTORY)
    sys.stdout.write(as_json(nodes) if args.format == "json" else as_markdown(nodes))
    return 0
