"""A built tree as the engine runs it: its root, and where each node was written.

The tree layer (:mod:`frog_bt.tree.loader`) builds it; the engine, observers and tools
read it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Protocol

import py_trees

from frog_bt.model.key import Scope

__all__ = ["Behaviour", "LoadedTree", "NodeTypes", "Path_", "Where"]

Path_ = tuple[str | int, ...]
Behaviour = py_trees.behaviour.Behaviour


class NodeTypes(Protocol):
    """What a tree was built with (a :class:`~frog_bt.tree.registry.NodeRegistry`)."""

    def names(self) -> list[str]:
        """Every node type name."""
        ...


@dataclass(frozen=True, slots=True)
class Where:
    file: str
    path: Path_
    line: tuple[int, int] | None = None  # (line, column) in the file, where known


@dataclass
class LoadedTree:
    """A built tree and where each node came from (for errors, render and telemetry)."""

    root: Behaviour
    file: str
    description: str = ""
    where: dict[int, Where] = field(default_factory=dict)  # id(node) -> file and path
    scopes: dict[int, Scope] = field(default_factory=dict)  # id(node) -> scope it starts
    factory: NodeTypes | None = None  # the node types it was built with

    def nodes(self) -> Iterator[Behaviour]:
        yield from self.root.iterate()
