"""Command-line values checked before anything connects: one line naming the option.

Every check raises :class:`~frog_bt.errors.UsageError` (``OPTION VALUE: what was
expected``), which the commands print as ``frog-bt: ...`` with exit code 2, so a
deployer never meets a traceback for a typo.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from frog_bt.config import Site
from frog_bt.errors import UsageError

TREE_HELP = (
    "tour tree (default: the packaged tour, trees/tour.yaml; 'frog-bt init DIR' copies it to edit)"
)
CONFIG_HELP = (
    "site configuration (default: the packaged config/site.yaml; "
    "'frog-bt init DIR' copies it to edit)"
)


def add_tree_and_config(p: argparse.ArgumentParser, *, tree: bool = True) -> None:
    """``--tree FILE`` and ``--config FILE``, with the same defaults in every command."""
    if tree:
        p.add_argument("--tree", type=Path, metavar="FILE", help=TREE_HELP)
    p.add_argument("--config", type=Path, metavar="FILE", help=CONFIG_HELP)


def add_tree_argument(p: argparse.ArgumentParser) -> None:
    """``[TREE]`` or ``--tree FILE``, and ``--config FILE`` (render, check)."""
    p.add_argument("tree", nargs="?", type=Path, metavar="TREE", help=TREE_HELP)
    p.add_argument(
        "--tree",
        dest="tree_option",
        type=Path,
        metavar="FILE",
        help="the same as TREE, as the other commands take it",
    )
    p.add_argument("--config", type=Path, metavar="FILE", help=CONFIG_HELP)


def tree_argument(args: argparse.Namespace) -> Path | None:
    """The tree given as TREE or --tree (absolute: the loader resolves includes against
    the tree's own folder); UsageError when both are given."""
    if args.tree and args.tree_option:
        raise UsageError("TREE", "", "give the tree once: TREE or --tree FILE")
    path = args.tree or args.tree_option
    return path.absolute() if path else None


def load_tree_argument(args: argparse.Namespace) -> tuple[Path | None, Site, Any]:
    """The tree given as TREE or --tree, the site config and the loaded tree; raises
    UsageError (both given) or DefinitionError (a bad file) for the command to report."""
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site

    path = tree_argument(args)
    site = load_site(args.config)
    return path, site, load_tree(path, site)


def writable_file(path: Path, option: str) -> Path:
    """``path`` if a file can be written there (its folder exists and is writable)."""
    if path.is_dir():
        raise UsageError(option, path, "is a directory; expected a file path")
    parent = path.parent
    if not parent.is_dir():
        what = "is not a directory" if parent.exists() else "does not exist"
        raise UsageError(option, path, f"cannot write there: {parent} {what}")
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise UsageError(option, path, "cannot write there: permission denied")
    return path


def rerun_spec(spec: str | None, option: str = "--rerun") -> str | None:
    """``spawn | save:FILE.rrd | connect[:URL] | serve | off``; ``off`` and none are None."""
    if spec is None or spec == "off":
        return None
    kind, _, rest = spec.partition(":")
    if kind == "save":
        if not rest:
            raise UsageError(option, spec, "expected save:FILE.rrd")
        try:
            writable_file(Path(rest), option)
        except UsageError as exc:
            raise UsageError(option, spec, exc.detail) from None
    elif kind not in ("spawn", "connect", "serve"):
        raise UsageError(option, spec, "expected spawn, save:FILE.rrd, connect[:URL], serve or off")
    return spec


def read_secret(site: Site) -> str | None:
    """The rosbridge auth secret: from the configured environment variable, else file."""
    links = site.links
    secret = os.environ.get(links.secret_env)
    if not secret and links.secret_file:
        try:
            secret = Path(links.secret_file).read_text(encoding="utf-8").strip()
        except OSError as exc:
            raise UsageError(
                "links.secret_file",
                links.secret_file,
                f"cannot read the rosbridge secret: {exc.strerror or exc}",
            ) from None
    return secret or None
