"""A node registry that also loads and exports trees: what a caller holds.

:class:`NodeFactory` is a :class:`~frog_bt.tree.registry.NodeRegistry` (the node types
by name) with :meth:`~NodeFactory.load` (the loader) and :meth:`~NodeFactory.export_xml`
(BehaviorTree.CPP v4). It sits above both, so that neither imports it back: the tree
package has no cycle, not even through an import inside a function.
"""

from __future__ import annotations

from pathlib import Path

from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.tree.loader import load_tree
from frog_bt.tree.registry import NodeRegistry

__all__ = ["NodeFactory"]


class NodeFactory(NodeRegistry):
    """Composites, decorators and leaves by the name a tree file gives them; loads and
    exports tree files with them."""

    def load(self, path: str | Path | None = None, site: Site | None = None) -> LoadedTree:
        """Load, expand, build and check a tree file with these node types."""
        return load_tree(path, site, self)

    def export_xml(self, path: Path, site: Site | None) -> str:
        """The tree file at ``path`` as BehaviorTree.CPP v4 XML, its node model from these
        types."""
        from frog_bt.tree.btcpp import tree_xml  # xml.etree: not needed to run a tree

        return tree_xml(path, site, self)
