"""Draw a tour tree as text, Graphviz DOT, Mermaid, an SVG/PNG image, or BehaviorTree.CPP
v4 XML (btcpp: Groot2 opens and edits it; `--tree FILE.xml` reads it back).

Loads and checks the site configuration and the tree as `frog-bt run` does (a bad
file: one line naming the file and the path in it, exit 2). Needs no robot and no
network; svg and png need Graphviz's `dot` program (exit 1 without it). Text
formats go to stdout unless -o FILE is given.

Each node shows its name, its type and its parameters (composites: memory,
policy); --keys adds each node's blackboard keys (`/key?`: an optional read).

Examples:

  frog-bt render                                 the tour as an indented tree
  frog-bt render --format unicode --keys         with guide lines and blackboard keys
  frog-bt render trees/recruit.yaml --format mermaid
  frog-bt render --format svg -o docs/tour-tree.svg
  frog-bt render --format btcpp -o tour.xml      for Groot2; frog-bt check tour.xml
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from frog_bt.behaviours import FACTORY
from frog_bt.commands.options import add_tree_argument, load_tree_argument
from frog_bt.errors import DefinitionError, UsageError, error_lines
from frog_bt.tree import render

FORMATS = ("ascii", "unicode", "dot", "svg", "png", "mermaid", "btcpp")


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_argument(p)
    p.add_argument(
        "-f", "--format", choices=FORMATS, default="ascii", help="output format (default: ascii)"
    )
    p.add_argument(
        "-o", "--output", type=Path, metavar="FILE", help="write to FILE instead of stdout"
    )
    p.add_argument(
        "--keys",
        action="store_true",
        help="show each node's blackboard keys (reads, optional reads?, writes)",
    )
    p.add_argument(
        "--rankdir",
        choices=("TB", "LR"),
        default="LR",
        help="graph direction for dot, svg, png and mermaid: LR left-to-right "
        "(default: a whole tour stays legible) or TB top-down",
    )


def btcpp_xml(path: Path | None, site: Any) -> str:
    """The tree as BehaviorTree.CPP v4 XML (:func:`frog_bt.tree.btcpp.tree_xml`)."""
    from frog_bt.tree.btcpp import tree_xml
    from frog_bt.tree.loader import DEFAULT_TREE

    return tree_xml(path or DEFAULT_TREE, site, FACTORY)


def draw(root: render.Node, fmt: str, *, keys: bool = False, rankdir: str = "LR") -> bytes:
    """The tree in ``fmt`` as bytes (text formats UTF-8); raises GraphvizError for svg/png."""
    if fmt in ("ascii", "unicode"):
        return render.text(root, unicode=fmt == "unicode", keys=keys).encode("utf-8")
    if fmt == "mermaid":
        return render.mermaid(root, keys=keys, rankdir=rankdir).encode("utf-8")
    graph = render.dot(root, keys=keys, rankdir=rankdir)
    return graph.encode("utf-8") if fmt == "dot" else render.graphviz(graph, fmt)


def run(args: argparse.Namespace) -> int:
    try:
        path, site, tree = load_tree_argument(args)
    except UsageError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    except DefinitionError as exc:
        for line in error_lines(exc):
            print(f"frog-bt: {line}", file=sys.stderr)
        return 2
    if args.format == "png" and args.output is None and sys.stdout.isatty():
        print("frog-bt: png is binary: give -o FILE (or redirect stdout)", file=sys.stderr)
        return 2
    data = btcpp_xml(path, site).encode("utf-8") if args.format == "btcpp" else None
    try:
        if data is None:
            data = draw(
                render.outline(tree.root), args.format, keys=args.keys, rankdir=args.rankdir
            )
    except render.GraphvizError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 1
    if args.output is None:
        try:
            sys.stdout.flush()
            sys.stdout.buffer.write(data)
            sys.stdout.buffer.flush()
        except BrokenPipeError:  # e.g. `| head`: the reader has what it wanted
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    try:
        args.output.write_bytes(data)
    except OSError as exc:
        print(f"frog-bt: {args.output}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    return 0
