"""A loaded tree as verify runs it: its nodes numbered in pre-order, each with what its
tick needs (kind, children, memory, attempts) and, for a leaf, its abstraction.

Compiled from the tree the loader built (:class:`~frog_bt.engine.loaded.LoadedTree`),
so that verify sees exactly the composites, decorators, ``when``, includes and stops of
the tree the executive runs. A decorator of the tour's own (a scope: face stream,
projector, checkpoint, location) passes its child's status through; ``OperatorSkip``
may be skipped by the operator.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any

import py_trees

from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.errors import TreeError
from frog_bt.model import keys
from frog_bt.model.key import Scope
from frog_bt.tree.composites import Parallel, Selector, Sequence
from frog_bt.tree.decorators import FailureIsSuccess, Retry, Timeout
from frog_bt.tree.leaf import Leaf
from frog_bt.tree.world import world_of
from frog_bt.verify.abstraction import Abstraction, abstraction_of
from frog_bt.verify.world import Role

Behaviour = py_trees.behaviour.Behaviour


class Kind(enum.Enum):
    SEQUENCE = "Sequence"
    SELECTOR = "Selector"
    PARALLEL = "Parallel"
    RETRY = "Retry"
    FAILURE_IS_SUCCESS = "FailureIsSuccess"
    TIMEOUT = "Timeout"
    SKIP = "OperatorSkip"
    PASS = "decorator"
    LEAF = "leaf"


@dataclass(eq=False, slots=True)
class CNode:
    """One node of the compiled tree."""

    index: int
    kind: Kind
    name: str
    type_name: str
    behaviour: Behaviour
    parent: int = -1
    children: tuple[int, ...] = ()
    end: int = 0  # one past the last node of its subtree (pre-order)
    memory: bool = False
    attempts: int | None = None
    policy_all: bool = True
    synchronise: bool = True
    keeps_success: bool = False  # a child of a synchronised Parallel: SUCCESS is kept
    abstraction: Abstraction = field(default_factory=Abstraction)
    declared: bool = True
    params: dict[str, Any] = field(default_factory=dict)
    reads_paused: bool = False
    dock: str = ""
    scope: Scope | None = None
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()

    def type_name_in(self, *names: str) -> bool:
        return any(c.__name__ in names for c in type(self.behaviour).__mro__)

    @property
    def role(self) -> Role:
        return self.abstraction.role if self.kind is Kind.LEAF else Role.NONE

    def label(self) -> str:
        return f"{self.type_name} {self.name!r}" if self.name != self.type_name else self.name


@dataclass(slots=True)
class Model:
    tree: LoadedTree
    nodes: list[CNode]
    real: bool = False  # compiled for the real tree's explorer (roles from ``world``)

    def named(self, name: str) -> list[CNode]:
        """The nodes with ``name`` (a name written once in an included file may name one
        node per stop)."""
        return [n for n in self.nodes if n.name == name]

    def undeclared(self) -> list[str]:
        """Leaf types with no declared world interface (no abstraction)."""
        return sorted({n.type_name for n in self.nodes if not n.declared})

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
                    + (
                        "(a `world` World on its class)"
                        if self.real
                        else "(a `verify` Abstraction on its class)"
                    ),
                )
            )
        return errors


def _kind(node: Behaviour) -> Kind:
    if isinstance(node, Sequence):
        return Kind.SEQUENCE
    if isinstance(node, Selector):
        return Kind.SELECTOR
    if isinstance(node, Parallel):
        return Kind.PARALLEL
    if isinstance(node, Retry):
        return Kind.RETRY
    if isinstance(node, FailureIsSuccess):
        return Kind.FAILURE_IS_SUCCESS
    if isinstance(node, Timeout):
        return Kind.TIMEOUT
    if isinstance(node, Leaf):
        return Kind.LEAF
    if any(c.__name__ == "OperatorSkip" for c in type(node).__mro__):
        return Kind.SKIP
    if node.children:
        return Kind.PASS
    raise TypeError(f"{node.name}: {type(node).__name__} is no node type verify knows")


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


def compile_tree(tree: LoadedTree, site: Site | None = None, real: bool = False) -> Model:
    """Number the nodes of ``tree`` and attach each leaf's abstraction (``real``: its
    role from the world interface its class declares, :mod:`frog_bt.tree.world`)."""
    dock = site.tour.dock if site is not None else "SHOP"
    nodes: list[CNode] = []

    def walk(b: Behaviour, parent: int) -> int:
        kind = _kind(b)
        n = CNode(len(nodes), kind, b.name, type(b).__name__, b, parent, dock=dock)
        nodes.append(n)
        params = getattr(b, "params", None)
        if params is not None and hasattr(params, "model_dump"):
            n.params = params.model_dump()
        if kind in (Kind.SEQUENCE, Kind.SELECTOR):
            n.memory = bool(getattr(b, "memory", False))
        if kind is Kind.PARALLEL:
            policy = getattr(b, "policy", None)
            n.policy_all = isinstance(policy, py_trees.common.ParallelPolicy.SuccessOnAll)
            n.synchronise = bool(getattr(policy, "synchronise", False))
        if kind is Kind.RETRY:
            n.attempts = n.params.get("attempts")
        if kind is Kind.LEAF and real:
            world = world_of(type(b))
            n.declared = world is not None
            n.abstraction = Abstraction(role=world.role if world is not None else Role.NONE)
        elif kind is Kind.LEAF:
            n.abstraction, n.declared = abstraction_of(type(b))
        reads = (*getattr(b, "reads", ()), *getattr(b, "optional_reads", ()))
        n.reads = _names(reads)
        n.writes = _names(getattr(b, "writes", ()))
        n.reads_paused = keys.PAUSED.name in n.reads
        n.scope = tree.scopes.get(id(b))
        children = [walk(c, n.index) for c in b.children]
        n.children = tuple(children)
        n.end = len(nodes)
        if kind is Kind.PARALLEL and n.policy_all and n.synchronise:
            for c in children:
                nodes[c].keeps_success = True
        return n.index

    walk(tree.root, -1)
    return Model(tree, nodes, real)
