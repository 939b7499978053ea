"""frog-bt's lean ticks are py_trees' own: the same statuses and the same nodes yielded,
tick by tick, for any tree of sequences, selectors, decorators and leaves."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import py_trees
from hypothesis import given, settings
from hypothesis import strategies as st

from frog_bt.engine import lean

Status = py_trees.common.Status
STATUSES = [Status.SUCCESS, Status.FAILURE, Status.RUNNING]


def scripted(base: type, script: list[Status]) -> Callable[[str], Any]:
    class Leaf(base):  # type: ignore[misc]
        def __init__(self, name: str) -> None:
            super().__init__(name)
            self.calls = 0

        def update(self) -> Status:
            self.calls += 1
            status: Status = script[(self.calls - 1) % len(script)]
            return status

    return Leaf


def build(shape: Any, lean_classes: bool, n: list[int]) -> py_trees.behaviour.Behaviour:
    """``shape``: a leaf's script (a list), or (kind, memory, children)."""
    n[0] += 1
    name = f"n{n[0]}"
    if isinstance(shape, list):
        base = lean.LeanBehaviour if lean_classes else py_trees.behaviour.Behaviour
        leaf: py_trees.behaviour.Behaviour = scripted(base, shape)(name)
        return leaf
    kind, memory, children = shape
    cls: Any
    built = [build(c, lean_classes, n) for c in children]
    if kind == "decorator":
        cls = lean.LeanDecorator if lean_classes else py_trees.decorators.Decorator

        class Pass(cls):  # type: ignore[misc]
            def update(self) -> Status:
                status: Status = self.decorated.status
                return status

        return Pass(name=name, child=built[0])
    if kind == "sequence":
        cls = lean.LeanSequence if lean_classes else py_trees.composites.Sequence
    else:
        cls = lean.LeanSelector if lean_classes else py_trees.composites.Selector
    composite: py_trees.behaviour.Behaviour = cls(name, memory=memory, children=built)
    return composite


leaves = st.lists(st.sampled_from(STATUSES), min_size=1, max_size=4)
shapes = st.recursive(
    leaves,
    lambda inner: st.one_of(
        st.tuples(st.just("decorator"), st.just(False), st.lists(inner, min_size=1, max_size=1)),
        st.tuples(
            st.sampled_from(["sequence", "selector"]),
            st.booleans(),
            st.lists(inner, min_size=1, max_size=4),
        ),
    ),
    max_leaves=10,
)


@settings(max_examples=150, deadline=None)
@given(shape=shapes, ticks=st.integers(min_value=1, max_value=6))
def test_lean_ticks_are_py_trees_ticks(shape: Any, ticks: int) -> None:
    theirs, ours = build(shape, False, [0]), build(shape, True, [0])
    for _ in range(ticks):
        yielded = ([n.name for n in theirs.tick()], [n.name for n in ours.tick()])
        assert yielded[1] == yielded[0]
        assert [(n.name, n.status) for n in ours.iterate()] == [
            (n.name, n.status) for n in theirs.iterate()
        ]
