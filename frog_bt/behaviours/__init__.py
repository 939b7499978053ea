"""Every leaf and scope of the tour, and the node factory that knows them.

:data:`FACTORY` is a :class:`~frog_bt.tree.factory.NodeFactory` with every leaf and decorator type
of this package registered; :func:`load_tree` loads a tree file with it.
"""

from __future__ import annotations

from pathlib import Path

from frog_bt.behaviours import (
    docking,
    engagement,
    help,
    location,
    navigation,
    operator,
    projector,
    recruit,
    safety,
    tour,
    visit,
)
from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.tree.factory import NodeFactory

__all__ = [
    "FACTORY",
    "docking",
    "engagement",
    "help",
    "load_tree",
    "location",
    "navigation",
    "operator",
    "projector",
    "recruit",
    "safety",
    "tour",
    "visit",
]

FACTORY = NodeFactory(LEAF_TYPES, DECORATOR_TYPES)


def load_tree(path: str | Path | None = None, site: Site | None = None) -> LoadedTree:
    """Load, expand, build and check a tree file (default ``trees/tour.yaml``) with the
    tour's node types."""
    return FACTORY.load(path, site)
