"""Write an editable copy of the tour tree files and the site configuration.

For a new site, or to change the tour on an installed robot without touching
Python: DIR/trees/*.yaml (tour.yaml and the files it includes) and
DIR/config/site.yaml, copied from the packaged ones. Then:

  frog-bt check/render/run/demo --tree DIR/trees/tour.yaml --config DIR/config/site.yaml

Existing files are left alone unless --force.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from frog_bt import resources


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", type=Path, metavar="DIR", help="where to write trees/ and config/")
    p.add_argument("--force", action="store_true", help="overwrite files that exist")


def copies(target: Path) -> list[tuple[Path, Path]]:
    """(packaged file, where it goes) for every file ``init`` writes."""
    out = [(src, target / "trees" / src.name)
           for src in sorted([*resources.tree_dir().glob("*.yaml"),
                              *resources.tree_dir().glob("*.schema.json")])]
    for src in (resources.site_dir() / resources.SITE_FILE,
                *resources.site_dir().glob("*.schema.json")):
        out.append((src, target / "config" / src.name))
    return out


def run(args: argparse.Namespace) -> int:
    plan = copies(args.dir)
    if not args.force:
        existing = [dst for _, dst in plan if dst.exists()]
        if existing:
            print(f"frog-bt: {existing[0]}: exists; give --force to overwrite "
                  f"({len(existing)} file{'s' if len(existing) > 1 else ''} would be)",
                  file=sys.stderr)
            return 2
    try:
        for src, dst in plan:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
    except OSError as exc:
        where = exc.filename or args.dir
        print(f"frog-bt: {where}: cannot write: {exc.strerror or exc}", file=sys.stderr)
        return 2
    for _, dst in plan:
        print(f"wrote {dst}")
    tree, site = args.dir / "trees" / resources.TREE_FILE, args.dir / "config" / resources.SITE_FILE
    print(f"\nEdit them, then:\n  frog-bt render --tree {tree} --config {site}\n"
          f"  frog-bt demo --tree {tree} --config {site}\n"
          f"  frog-bt run --tree {tree} --config {site} ...")
    return 0
