"""A typed blackboard key: what a value of a tour is called, its type, who writes it and
how long it lives. The declarations themselves are in :mod:`frog_bt.model.keys` (and, for
the robot's inputs, beside their topics in :mod:`frog_bt.model.wire`).

A leaf names the keys it reads and writes with these objects (``reads = (keys.POSE,)``),
gets typed values back from :meth:`~frog_bt.tree.node.Declared.get`, and the load-time
checks (data flow, types), blame, telemetry, replay, ``frog-bt leaves``, the JSON Schema
and docs/TREES.md all read the same declarations. This module imports nothing of frog-bt:
it is the bottom of the kernel.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

T = TypeVar("T")
T_co = TypeVar("T_co", covariant=True)


class Source(enum.Enum):
    """Who writes a key."""

    INPUT = "input"  # the pre-tick snapshot, from the robot or the front end
    LEAF = "leaf"  # tree nodes (each declares it in ``writes``)
    EXECUTIVE = "executive"  # the executive between ticks (the tour's bookkeeping)


class Scope(enum.IntEnum):
    """How long a value lives. Starting a scope clears every key of that scope and of the
    narrower ones, so that an optional read never sees a value of another scope."""

    PROCESS = 0  # as long as the executive (inputs, the last tour state)
    TOUR = 1  # one tour: cleared when a tour starts
    VISITOR = 2  # one recruitment: cleared when the search for a visitor starts anew
    STOP = 3  # one stop of the tour: cleared when a stop starts

    def within(self, scope: Scope) -> bool:
        """Does a value of this scope end when ``scope`` starts?"""
        return self >= scope and self is not Scope.PROCESS


class Readable(Generic[T_co]):
    """A key as a read sees it: what :meth:`Board.get <frog_bt.engine.blackboard.Board.get>`
    and a leaf's ``get`` take. :class:`Key` is invariant in its value type, so that a write
    of the wrong type is an error; a read takes this covariant view of it, so that
    ``bool(board.get(keys.PAUSED))`` or an f-string, whose context is ``object``, still
    reads a ``Key[bool]`` (mypy infers from that outer context first: python/mypy#17654)."""

    __slots__ = ()
    name: str
    lasting: bool


@dataclass(frozen=True, slots=True, eq=False)
class Key(Readable[T]):
    """One value of the tour: ``name`` (as tree files, docs and telemetry show it), the
    ``type`` of its value (None is always allowed: not written yet, or cleared), its
    ``source``, its ``scope`` and what it means (``doc``). A ``lasting`` key is the
    executive's, not one tree's: what people decided (in service, paused) and the tours'
    bookkeeping outlive a reload (:class:`~frog_bt.engine.standing.Standing`). Keys compare
    by identity: each is declared once."""

    name: str
    type: Any
    source: Source
    scope: Scope
    doc: str
    lasting: bool = False  # kept by the executive across trees (a reload), not by one core

    def __repr__(self) -> str:
        return self.name

    @property
    def type_name(self) -> str:
        return type_name(self.type)


@dataclass(frozen=True, slots=True)
class Reading(Generic[T]):
    """A value and the project-clock time it was received."""

    value: T
    at: float

    def age(self, now: float) -> float:
        return now - self.at


def type_name(t: Any) -> str:
    return getattr(t, "__name__", None) or str(t).replace("typing.", "")
