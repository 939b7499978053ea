"""The composites a tree file can name, with their parameters declared once.

Each is py_trees' own composite, observed (:mod:`frog_bt.engine.observed`), with a
``Params`` model like a leaf's: the loader validates a tree file's entry with it, and
``frog-bt leaves``, the JSON Schema and docs/TREES.md read the same declaration.
``scope`` makes the composite start a scope: its keys are cleared each time it starts
(:class:`~frog_bt.model.key.Scope`).
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

import py_trees
from pydantic import Field

from frog_bt.engine.lean import LeanSelector, LeanSequence
from frog_bt.engine.observed import Observed
from frog_bt.model.key import Scope
from frog_bt.tree.node import Params
from frog_bt.tree.world import World

Behaviour = py_trees.behaviour.Behaviour
ScopeName = Literal["tour", "visitor", "stop"]
SCOPE_DOC = (
    "the scope this part starts: its values (and narrower ones) are cleared each "
    "time it starts (tour, visitor, stop)"
)


class _Composite(Observed, py_trees.composites.Composite):
    Params: ClassVar[type[Params]]
    world = World(
        state=("current_child",),
        key=lambda n: n.children.index(n.current_child) if n.current_child is not None else -1,
    )

    def initialise(self) -> None:
        self.start_scope()  # py_trees calls it from the tick, as the composite starts

    @classmethod
    def build(cls, name: str, params: Any, children: list[Behaviour]) -> _Composite:
        """The node for a tree file's entry: py_trees' composite, starting its scope."""
        node = cls._make(name, params, children)
        if params.scope is not None:
            node.scope = Scope[params.scope.upper()]
        return node

    @classmethod
    def _make(cls, name: str, params: Any, children: list[Behaviour]) -> _Composite:
        return cls(name, memory=params.memory, children=children)  # type: ignore[call-arg]


class Sequence(_Composite, LeanSequence):
    """Runs its children in order; SUCCESS when all succeed, FAILURE at the first that
    fails."""

    class Params(Params):
        memory: bool = Field(
            description="true: resume at the running child; false: re-check every child each tick"
        )
        scope: ScopeName | None = Field(None, description=SCOPE_DOC)


class Selector(_Composite, LeanSelector):
    """Tries its children in order; SUCCESS at the first that succeeds, FAILURE when all
    fail."""

    class Params(Params):
        memory: bool = Field(
            description="true: resume at the running child; false: try from the first each tick"
        )
        scope: ScopeName | None = Field(None, description=SCOPE_DOC)


class Parallel(_Composite, py_trees.composites.Parallel):
    """Ticks all its children every tick; FAILURE as soon as one fails."""

    class Params(Params):
        policy: Literal["all", "one"] = Field(
            "all", description="SUCCESS when all children / one child succeed"
        )
        synchronise: bool = Field(
            True, description="with policy all: a succeeded child is not ticked again"
        )
        scope: ScopeName | None = Field(None, description=SCOPE_DOC)

    @classmethod
    def _make(cls, name: str, params: Any, children: list[Behaviour]) -> _Composite:
        policy = (
            py_trees.common.ParallelPolicy.SuccessOnAll(synchronise=params.synchronise)
            if params.policy == "all"
            else py_trees.common.ParallelPolicy.SuccessOnOne()
        )
        return cls(name, policy=policy, children=children)


COMPOSITES: dict[str, type[_Composite]] = {
    "Sequence": Sequence,
    "Selector": Selector,
    "Parallel": Parallel,
}
