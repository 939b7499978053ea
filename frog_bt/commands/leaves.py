"""List every node type a tree file can name: parameters, blackboard keys, what it does.

The catalogue comes from the code itself (the registered leaves and decorators,
and the composites), so it is always the one the installed `frog-bt` accepts.
`docs/TREES.md`'s node reference is this command's Markdown; after it come the
properties `frog-bt verify` proves and the templates a tree file may add.

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
    if args.format == "json":
        sys.stdout.write(as_json(nodes))
        return 0
    sys.stdout.write(as_markdown(nodes) + "\n" + properties_markdown())
    return 0


def properties_markdown() -> str:
    """What ``frog-bt verify`` proves of every tree, and the templates a tree file may add
    under ``properties:`` (nodes named as in the tree)."""
    from frog_bt.verify.designer import Between, Reaches, Together
    from frog_bt.verify.properties import MEANING

    out = ["### Properties (`frog-bt verify`)\n", "| built in | what it means |", "|---|---|"]
    out += [f"| `{name}` | {meaning} |" for name, meaning in MEANING.items()]
    out += [
        "",
        "| template (`properties:` in a tree file) | fields | what it means |",
        "|---|---|---|",
    ]
    for cls in (Together, Reaches, Between):
        fields = ", ".join(f"`{name}`" for name in cls.model_fields)
        doc = (cls.__doc__ or "").strip().splitlines()[0]
        out.append(f"| `{cls.__name__}` | {fields} | {doc} |")
    return "\n".join(out) + "\n"
