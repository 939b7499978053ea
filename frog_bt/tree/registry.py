"""The node types a tree file can name, as one instance (BehaviorTree.CPP's
``BehaviorTreeFactory``): the composites and decorators of this package, and the leaves
registered into it.

The tree layer never imports the leaves: :mod:`frog_bt.behaviours` builds the tour's
factory (:data:`frog_bt.behaviours.FACTORY`) and a test builds its own with a leaf of
its own, so nothing global changes. The loader (:mod:`frog_bt.tree.loader`), the
BehaviorTree.CPP export (:mod:`frog_bt.tree.btcpp`) and the catalogue read a registry;
:class:`~frog_bt.tree.factory.NodeFactory` adds loading and exporting on top.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

from frog_bt.engine.loaded import Behaviour
from frog_bt.tree.composites import COMPOSITES
from frog_bt.tree.decorators import DECORATORS, FrogDecorator
from frog_bt.tree.leaf import Leaf

__all__ = ["NodeRegistry"]

L = TypeVar("L", bound=type[Leaf])
D = TypeVar("D", bound=type[FrogDecorator])


class NodeRegistry:
    """Composites, decorators and leaves by the name a tree file gives them."""

    def __init__(
        self, leaves: Iterable[type[Leaf]] = (), decorators: Iterable[type[FrogDecorator]] = ()
    ) -> None:
        self.composites = dict(COMPOSITES)
        self.decorators: dict[str, type[FrogDecorator]] = dict(DECORATORS)
        self.leaves: dict[str, type[Leaf]] = {}
        for leaf in leaves:
            self.register(leaf)
        for decorator in decorators:
            self.register_decorator(decorator)

    def _free(self, name: str) -> None:
        if name in self.leaves or name in self.composites or name in self.decorators:
            raise ValueError(f"node type {name} registered twice")

    def register(self, cls: L) -> L:
        """Add a leaf type under its class name (a name registered twice is an error)."""
        self._free(cls.__name__)
        self.leaves[cls.__name__] = cls
        return cls

    def register_decorator(self, cls: D) -> D:
        """Add a decorator type (a scope) under its class name."""
        self._free(cls.__name__)
        self.decorators[cls.__name__] = cls
        return cls

    def names(self) -> list[str]:
        """Every type name, composites first."""
        return [*self.composites, *self.decorators, *self.leaves]

    def type_of(self, name: str) -> type[Behaviour]:
        """The class a type name stands for; KeyError for an unknown one."""
        found = self.composites.get(name) or self.decorators.get(name) or self.leaves.get(name)
        if found is None:
            raise KeyError(name)
        return found
