"""A loaded tree as verify sees it: its nodes numbered in pre-order, each with what the
properties and the report need (its name, parent and children, a retry's attempts, the
keys it reads and writes, its scope) and, for a leaf, its role to the built-in
properties, from the world interface its class declares (:mod:`frog_bt.tree.world`).

Compiled from the tree the loader built (:class:`~frog_bt.engine.loaded.LoadedTree`):
the explorer (:mod:`.real`) ticks that very tree; this numbering only names its nodes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import py_trees

from frog_bt.engine.loaded import LoadedTree
from frog_bt.errors import TreeError
from frog_bt.model.key import Scope
from frog_bt.tree.decorators import Retry
from frog_bt.tree.leaf import Leaf
from frog_bt.tree.world import world_of
from frog_bt.verify.world import Role

Behaviour = py_trees.behaviour.Behaviour


@dataclass(eq=False, slots=True)
class CNode:
    """One node of the compiled tree."""

    index: int
    name: str
    type_name: str
    behaviour: Behaviour
    parent: int = -1
    children: tuple[int, ...] = ()
    attempts: int | None = None  # a Retry's bound (None: for ever)
    role: Role = Role.NONE  # a leaf's, from its class's ``world``
    declared: bool = True  # a leaf whose class declares its world interface
    scope: Scope | None = None
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()

    def label(self) -> str:
        return f"{self.type_name} {self.name!r}" if self.name != self.type_name else self.name


@dataclass(slots=True)
class Model:
    tree: LoadedTree
    nodes: list[CNode]

    def named(self, name: str) -> list[CNode]:
        """The nodes with ``name`` (a name written once in an included file may name one
        node per stop)."""
        return [n for n in self.nodes if n.name == name]

    def undeclared_errors(self) -> list[TreeError]:
        """One error per leaf type with no declared world interface, at its first node:
        verify cannot say what such a leaf may do, so it proves nothing about the tree."""
        first: dict[str, CNode] = {}
        for n in self.nodes:
            if not n.declared:
                first.setdefault(n.type_name, n)
        errors = []
        for type_name, n in first.items():
            at = self.tree.where.get(id(n.behaviour))
            errors.append(
                TreeError(
                    at.file if at else self.tree.file,
                    at.path if at else (),
                    f"leaf type {type_name} declares no world interface for verify "
                    "(a `world` World on its class)",
                )
            )
        return errors


def _names(ks: Any) -> tuple[str, ...]:
    return tuple(k.name for k in ks)


def preorder(root: Behaviour) -> list[Behaviour]:
    """The nodes under ``root``, parents before children (as :func:`compile_tree` numbers
    them; py_trees' ``iterate`` gives children first)."""
    out: list[Behaviour] = []
    stack = [root]
    while stack:
        node = stack.pop()
        out.append(node)
        stack.extend(reversed(node.children))
    return out


def compile_tree(tree: LoadedTree) -> Model:
    """Number the nodes of ``tree``; each leaf's role from the world interface its class
    declares (none declared: an error, :meth:`Model.undeclared_errors`)."""
    nodes: list[CNode] = []

    def walk(b: Behaviour, parent: int) -> int:
        n = CNode(len(nodes), b.name, type(b).__name__, b, parent)
        nodes.append(n)
        if isinstance(b, Retry):
            n.attempts = b.params.attempts
        if isinstance(b, Leaf):
            world = world_of(type(b))
            n.declared = world is not None
            n.role = world.role if world is not None else Role.NONE
        reads = (*getattr(b, "reads", ()), *getattr(b, "optional_reads", ()))
        n.reads = _names(reads)
        n.writes = _names(getattr(b, "writes", ()))
        n.scope = tree.scopes.get(id(b))
        n.children = tuple(walk(c, n.index) for c in b.children)
        return n.index

    walk(tree.root, -1)
    return Model(tree, nodes)
