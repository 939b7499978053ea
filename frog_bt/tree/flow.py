"""The order-aware data-flow check: every key a node needs is written before it runs.

For each node the check computes the keys *surely written* when it starts (on
every path that reaches it), and after it succeeds:

* a ``Sequence`` runs its children in order, each only after the ones before it
  succeeded: child *i* starts with what children *0..i-1* surely wrote;
* a ``Selector`` tries its children in turn, each only after the ones before it
  *failed*: every child starts with what the selector started with, and after
  it only what *every* child surely writes is sure;
* a ``Parallel``'s children start together (a sibling may not have run yet);
* a decorator's child starts with what the decorator started with, plus what
  the decorator itself provides to it while it runs (``provides``, e.g. the face
  stream's samples); after it come the child's keys and the decorator's own
  ``writes``, except for a decorator that may succeed without its child
  (``skips_child``: a resumed checkpoint) and one whose child may fail
  (``child_may_fail``: ``FailureIsSuccess``), after which nothing of the child's
  is sure;
* a leaf needs its ``reads`` (not its ``optional_reads``), and surely wrote its
  ``writes`` once it succeeded;
* a node that starts a *scope* (each tour stop of a ``foreach``, ``scope:`` in a tree
  file) starts without the keys of that scope and the narrower ones (each key declares
  its :class:`~frog_bt.model.key.Scope`): a value left over from an earlier stop or
  from an earlier visitor's introduction is never this one's. At run time the same
  node clears those keys when it starts, so optional reads never see them either.

The input and executive keys (the wire table's, ``/now``, ``/events``, ...) are always
there.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import py_trees

from frog_bt.model.key import Key, Scope
from frog_bt.model.keys import always

Behaviour = py_trees.behaviour.Behaviour
Keys = frozenset[Key[Any]]


@dataclass(frozen=True, slots=True)
class Gap:
    """A node that reads a key no node surely writes before it."""

    node: Behaviour
    key: Key[Any]
    writers: tuple[Behaviour, ...]  # nodes that write it elsewhere (none: nothing does)
    scope: Scope | None  # the scope that dropped an earlier value, if one did


def gaps(root: Behaviour) -> list[Gap]:
    """Every read no writer surely precedes, in tree order."""
    found: list[Gap] = []
    writers: dict[Key[Any], list[Behaviour]] = {}
    for node in root.iterate():
        for key in getattr(node, "writes", ()):
            writers.setdefault(key, []).append(node)

    def need(node: Behaviour, have: Keys, lost: dict[Key[Any], Scope]) -> None:
        for key in getattr(node, "reads", ()):
            if key not in have:
                found.append(
                    Gap(
                        node,
                        key,
                        tuple(w for w in writers.get(key, ()) if w is not node),
                        lost.get(key),
                    )
                )

    def visit(node: Behaviour, have: Keys, lost: dict[Key[Any], Scope]) -> Keys:
        # The node's classes by their MRO, not isinstance: py_trees' Behaviour is an ABC,
        # whose first check of each leaf class against each composite walks every subclass
        # (a third of loading the tour tree, at start-up).
        mro = type(node).__mro__
        scope: Scope | None = getattr(node, "scope", None)
        if scope is not None:
            gone = frozenset(k for k in have if k.scope.within(scope))
            lost = {**lost, **{k: scope for k in gone}}
            have = have - gone
        need(node, have, lost)
        children = list(node.children)
        if py_trees.composites.Sequence in mro:
            for child in children:
                have = visit(child, have, lost)
            return have
        if py_trees.composites.Selector in mro:
            outs = [visit(child, have, lost) for child in children]
            return _all(outs, have)
        if py_trees.composites.Parallel in mro:
            assert isinstance(node, py_trees.composites.Parallel)  # (cached by now)
            outs = [visit(child, have, lost) for child in children]
            policy = node.policy
            if isinstance(policy, py_trees.common.ParallelPolicy.SuccessOnAll):
                return have.union(*outs)
            return _all(outs, have)
        own = frozenset(getattr(node, "writes", ()))
        if py_trees.decorators.Decorator in mro:
            assert isinstance(node, py_trees.decorators.Decorator)  # (cached by now)
            provides: Callable[[], Iterable[Key[Any]]] | None = getattr(node, "provides", None)
            given = have | frozenset(provides() if provides is not None else ())
            after = visit(node.decorated, given, lost)
            if getattr(node, "child_may_fail", False):
                return have | (own if not getattr(node, "skips_child", False) else frozenset())
            if getattr(node, "skips_child", False):
                return have | (own & after)
            return after | own
        return have | own

    visit(root, always(), {})
    return found


def _all(outs: list[Keys], have: Keys) -> Keys:
    """What every alternative surely wrote (an empty composite writes nothing)."""
    if not outs:
        return have
    common = outs[0]
    for out in outs[1:]:
        common &= out
    return have | common
