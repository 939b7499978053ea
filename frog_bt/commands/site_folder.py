"""A site folder made by ``frog-bt init``, found the way git finds its repository.

Every command that takes ``--tree`` / ``--config`` (or ``TREE``) uses, when they are not
given, ``trees/tour.yaml`` and ``config/site.yaml`` of the nearest folder, from the
working directory up, that has them; the packaged files only when there is none. A
command that found one says so on stderr, naming the files it uses.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from frog_bt import resources

TREE = Path("trees") / resources.TREE_FILE
SITE = Path("config") / resources.SITE_FILE


def find(start: Path | None = None) -> Path | None:
    """The nearest folder from ``start`` (default: the working directory) up that has
    ``trees/tour.yaml`` or ``config/site.yaml``; None when none has, or when it is the
    checkout whose files are the packaged ones."""
    here = (start or Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / TREE).is_file() or (folder / SITE).is_file():
            packaged = (resources.tree_dir() / resources.TREE_FILE).resolve()
            return None if (folder / TREE).resolve() == packaged else folder
    return None


def apply(args: argparse.Namespace, start: Path | None = None) -> list[Path]:
    """Fill the tree and config options the command line left out from the site folder;
    the files taken (also named on stderr)."""
    has_tree = hasattr(args, "tree")
    has_config = hasattr(args, "config")
    if not (has_tree or has_config):
        return []
    tree_given = bool(getattr(args, "tree", None) or getattr(args, "tree_option", None))
    if tree_given and (not has_config or args.config is not None):
        return []
    folder = find(start)
    if folder is None:
        return []
    taken: list[Path] = []
    if has_tree and not tree_given and (folder / TREE).is_file():
        args.tree = folder / TREE
        taken.append(args.tree)
    if has_config and args.config is None and (folder / SITE).is_file():
        args.config = folder / SITE
        taken.append(args.config)
    if taken:
        print(
            f"frog-bt: site folder {folder}: using {', '.join(str(p) for p in taken)}",
            file=sys.stderr,
        )
    return taken
