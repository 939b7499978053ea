"""Which values on the board are part of a state: those some node may still read.

Two states that differ only in a value no node will read before it is cleared behave
alike: keeping such a value in the state key only tells alike states apart (the abort
reason of the last tour, the engagement of the last stop, the visitor of the last
tour). A key's value is *live* in a state when the operator reads it
(``engine/operator.py``; ``/home`` and ``/abort_reason`` only as set or not), or when
some node may read it before it is cleared. A node that starts a scope clears the
scope's keys (and those of narrower scopes, :class:`~frog_bt.model.key.Scope`) as it
starts; so, from the state's running nodes and memory positions, the walk below asks
which readers can tick before a clearing start:

* a running node goes on: its current child (a memory composite's), then the children
  after it, each fresh; a composite without memory ticks every child afresh; a retry
  may start its child afresh; the root starts afresh once it ends (the tour loops);
* a node that starts afresh and clears the key hides its whole subtree;
* in a sequence, a child that surely cleared the key on its way to success hides the
  children after it (a selector's failed child may not have: every child counts);
* a checkpoint that may skip its child (a resumed tour: ``/resume`` set) neither clears
  nor hides;
* a decorator that succeeds only with its child (``World.passes``) cleared what its
  child surely cleared;
* in a sequence, a child that writes the key as it succeeds (``World.sets``) hides the
  children after it, as one that cleared it;
* a read a node type ``ignores`` (``World.ignores``: the value changes none of its
  outcomes under its world abstraction) is not a read.

Writes are not counted (a value written before every read would be dead too):
conservative, never unsound. The keys the pre-tick snapshot writes anew before every
tick (the robot's inputs, the clock, the newest goal) are never part of the board's
state: they are derived from the world and the engine, which the state keeps.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import Any

import py_trees

from frog_bt.engine.loaded import LoadedTree
from frog_bt.model import keys
from frog_bt.model.key import Key
from frog_bt.tree.world import world_of

Behaviour = py_trees.behaviour.Behaviour
RUNNING = py_trees.common.Status.RUNNING
# what the operator reads of the board (engine/operator.py) besides the tree's nodes
# (``/skip`` too, only to add one to it)
_OPERATOR: tuple[Key[Any], ...] = (
    *(keys.TOUR_STATE, keys.HOME, keys.ABORT_REASON, keys.PAUSED, keys.IN_SERVICE),
    *(keys.HELP, keys.HELP_ANSWER, keys.DOCKING),
)
OPERATOR_READS: frozenset[Key[Any]] = frozenset(_OPERATOR)


# the operator asks of these only whether they are set
PRESENCE: frozenset[Key[Any]] = frozenset({keys.HOME, keys.ABORT_REASON})


class Liveness:
    """The live keys of a tree in a state (cached per running nodes and positions)."""

    def __init__(
        self,
        tree: LoadedTree,
        nodes: Sequence[Behaviour],
        index: Mapping[int, int],
        derived: Collection[Key[Any]],
    ) -> None:
        self.nodes = nodes
        self.index = index
        self.scope = [tree.scopes.get(id(n)) for n in nodes]
        self.reads: dict[Key[Any], set[int]] = {}
        self.late: dict[Key[Any], set[int]] = {}  # read only once the child succeeded
        for i, node in enumerate(nodes):
            world = world_of(type(node))
            late = set(world.late) if world is not None else set()
            for key in _reads(node):
                if key not in derived:
                    into = self.late if key.name in late and node.children else self.reads
                    into.setdefault(key, set()).add(i)
        self.operator = OPERATOR_READS - PRESENCE - set(derived)
        # keys every reader reads only as true or false (declared: ``World.truthy``)
        truthy: dict[Key[Any], bool] = {}
        for node in nodes:
            world = world_of(type(node))
            said = set(world.truthy) if world is not None else set()
            for key in _reads(node):
                truthy[key] = truthy.get(key, True) and key.name in said
        self.truthy = frozenset(k for k, only in truthy.items() if only) - (
            OPERATOR_READS - PRESENCE
        )
        self.children = [[index[id(c)] for c in n.children] for n in nodes]
        self.memory = [bool(getattr(n, "memory", False)) for n in nodes]
        self.kind = [_kind(n) for n in nodes]
        self.skips = [bool(getattr(n, "skips_child", False)) for n in nodes]
        # decorators that succeed only when their child did (``World.passes``)
        self.passes = [bool(w.passes) if (w := world_of(type(n))) else False for n in nodes]
        # the keys each node surely writes as it succeeds (``World.sets``)
        self.sets = [
            frozenset(w.sets) if (w := world_of(type(n))) is not None else frozenset()
            for n in nodes
        ]
        self._cache: dict[tuple[object, ...], tuple[frozenset[Key[Any]], frozenset[Key[Any]]]] = {}

    def live(
        self, running: tuple[tuple[int, int], ...], resuming: bool
    ) -> tuple[frozenset[Key[Any]], frozenset[Key[Any]]]:
        """(the keys whose values are state, the keys only whether set is): ``running``
        the running nodes with their current child's position (-1: none), pre-order;
        ``resuming``: a checkpoint may still skip its child (``/resume`` set)."""
        sig = (running, resuming)
        found = self._cache.get(sig)
        if found is None:
            walk = _Walk(self, dict(running), resuming)
            values = {
                k
                for k in {*self.reads, *self.late}
                if walk.exposed(k, self.reads.get(k, set()), self.late.get(k, set()))
            }
            values |= self.operator
            found = (frozenset(values), PRESENCE - values)
            self._cache[sig] = found
        return found


def _reads(node: Behaviour) -> list[Key[Any]]:
    """The keys ``node`` reads, less those its type ``ignores`` (``World.ignores``)."""
    world = world_of(type(node))
    ignored = set(world.ignores) if world is not None else set()
    found = (*getattr(node, "reads", ()), *getattr(node, "optional_reads", ()))
    return [k for k in found if k.name not in ignored]


def _kind(node: Behaviour) -> str:
    if isinstance(node, py_trees.composites.Sequence):
        return "sequence"
    if isinstance(node, py_trees.composites.Selector):
        return "selector"
    if isinstance(node, py_trees.composites.Parallel):
        return "parallel"
    if isinstance(node, py_trees.decorators.Retry):
        return "retry"
    return "decorator" if node.children else "leaf"


class _Walk:
    """One state's walk for one key at a time (see the module's docstring)."""

    def __init__(self, of: Liveness, running: dict[int, int], resuming: bool) -> None:
        self.of, self.running, self.resuming = of, running, resuming

    def exposed(self, key: Key[Any], readers: set[int], late: set[int]) -> bool:
        self.key, self.readers, self.late_readers = key, readers, late
        self._clears: dict[int, bool] = {}
        return (0 in self.running and self._on(0)) or self._fresh(0)

    def _skips(self, i: int) -> bool:
        return self.resuming and self.of.skips[i]

    def _passes(self, i: int) -> bool:
        return self.of.passes[i] and not self._skips(i)

    def _clears_at(self, i: int) -> bool:
        s = self.of.scope[i]
        return (
            s is not None
            and not self.key.lasting
            and self.key.scope.within(s)
            and not self._skips(i)
        )

    def _starts_clear(self, i: int) -> bool:
        """Starting ``i`` afresh clears the key before anything under it reads."""
        if self._clears_at(i):
            return True
        kids = self.of.children[i]
        if not kids or self._skips(i) or i in self.readers:
            return False
        return self._starts_clear(kids[0])

    def _succeeds_cleared(self, i: int) -> bool:
        """``i`` succeeded from a fresh start: it surely cleared (or wrote) the key on the
        way."""
        found = self._clears.get(i)
        if found is None:
            kind, kids = self.of.kind[i], self.of.children[i]
            if self._starts_clear(i) or self.key.name in self.of.sets[i]:
                found = True
            elif kind == "sequence":
                found = any(self._succeeds_cleared(c) for c in kids)
            elif kind in ("selector", "parallel"):
                found = bool(kids) and all(self._succeeds_cleared(c) for c in kids)
            elif kind == "retry" or (kind == "decorator" and self._passes(i)):
                found = self._succeeds_cleared(kids[0])
            else:
                found = False
            self._clears[i] = found
        return found

    def _fresh(self, i: int) -> bool:
        """May a reader under ``i``, started afresh, read the value before it is cleared?"""
        if self._clears_at(i):
            return False
        if i in self.readers:
            return True
        kids = self.of.children[i]
        if self.of.kind[i] == "sequence":
            return self._in_order(kids)
        if i in self.late_readers and not self._succeeds_cleared(kids[0]):
            return True
        return any(self._fresh(c) for c in kids)

    def _in_order(self, kids: list[int]) -> bool:
        """Children ticked one after another's success, each afresh."""
        for c in kids:
            if self._fresh(c):
                return True
            if self._succeeds_cleared(c):
                return False
        return False

    def _rest_clears(self, i: int) -> bool:
        """``i`` runs now: on its way to success it surely clears (or writes) the key."""
        if i not in self.running:
            return self._succeeds_cleared(i)
        kids, kind = self.of.children[i], self.of.kind[i]
        if not kids:
            return self.key.name in self.of.sets[i]
        at = self.running.get(i, -1)
        if kind == "sequence" and self.of.memory[i] and 0 <= at < len(kids):
            current = kids[at]
            rest = (
                self._rest_clears(current)
                if current in self.running
                else self._succeeds_cleared(current)
            )
            return rest or any(self._succeeds_cleared(c) for c in kids[at + 1 :])
        if kind == "decorator" and self._passes(i):
            return self._rest_clears(kids[0])
        return False

    def _on(self, i: int) -> bool:
        """``i`` runs now: may a reader under it read the value before it is cleared?"""
        kids, kind = self.of.children[i], self.of.kind[i]
        if i in self.readers:
            return True
        if i in self.late_readers and not (kids and self._rest_clears(kids[0])):
            return True
        at = self.running.get(i, -1)
        if kind in ("sequence", "selector") and self.of.memory[i] and 0 <= at < len(kids):
            current = kids[at]
            if (current in self.running and self._on(current)) or (
                current not in self.running and self._fresh(current)
            ):
                return True
            later = kids[at + 1 :]  # the current child's own clearing is behind it
            if kind == "sequence" and current in self.running and self._rest_clears(current):
                return False  # it writes the key as it succeeds: the value now is dead
            if kind == "sequence":
                return self._in_order(later)
            return any(self._fresh(c) for c in later)
        if kind == "retry" and kids and self._fresh(kids[0]):
            return True
        return any(self._on(c) if c in self.running else self._fresh(c) for c in kids)
