"""Every status change of a frog-bt tree, seen without patching py_trees; and scopes.

py_trees changes a node's status in two places: in its ``tick`` (the tick
yields every node it reaches) and in its ``stop`` (which yields nothing). Every
node a tree file can build is one of our classes — leaves, decorators and the
composites below — and their ``stop`` reports the node to ``stop_log`` when one
is attached (:class:`~frog_bt.engine.core.Core` attaches its own). Observers such as
telemetry then follow the tree in O(active path), not O(tree).

Each core has its own :class:`Trace` (handed to every node in ``setup(trace=...)``):
which nodes are ticking or stopping now, innermost last (a command sent now is the last
one's doing: blame), and which nodes with reads ended in the current tick (what decided
a command sent later in the same tick). Nothing here is global.

A node that starts a scope (each stop of a ``foreach``, ``scope:`` in a tree file) clears
that scope's keys on the board (``setup(board=...)``) each time it starts.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import py_trees

from frog_bt.model.key import Scope

if TYPE_CHECKING:
    from frog_bt.engine.blackboard import Board
    from frog_bt.engine.faults import Faults

Behaviour = py_trees.behaviour.Behaviour


@dataclass(slots=True)
class Trace:
    """What one core's tree is doing now (blame reads it)."""

    acting: list[Behaviour] = field(default_factory=list)  # ticking or stopping, innermost last
    decided: list[Behaviour] = field(default_factory=list)  # nodes with reads ended this tick

    def current(self) -> Behaviour | None:
        """The innermost frog-bt node ticking or stopping now, if any."""
        return self.acting[-1] if self.acting else None


class Role(enum.Enum):
    """What the executive asks of a node, by what it declares rather than by its class."""

    STOP = "stop"  # a stop being visited or driven to: what ``skip`` leaves (its stop_poi())
    SEEK = "seek"  # the search for a visitor (an alert when it runs too long)


class Observed:
    """Mixin (before the py_trees base): ``stop`` appends the node to ``stop_log`` (and
    runs py_trees' stop without formatting its debug message unless py_trees' debug
    logging is on: :data:`_PY_TREES_STOPS`); a node
    with a ``scope`` clears it when it starts (:meth:`start_scope`); ``role`` says what the
    executive may ask of it (:class:`Role`)."""

    stop_log: list[Behaviour] | None = None
    scope: Scope | None = None  # set by the loader on a node that starts a scope
    role: Role | None = None
    status: py_trees.common.Status  # the py_trees base's
    _trace: Trace | None = None
    _board: Board | None = None
    _faults: Faults | None = None  # the executive's (from ctx): a terminate's failure counted

    def stop_poi(self) -> str:
        """A :attr:`Role.STOP` node's stop: the POI a skip would leave."""
        raise NotImplementedError(f"{type(self).__name__} is not a stop")

    def setup(self, **kwargs: Any) -> None:
        self._trace = kwargs.get("trace")
        self._board = kwargs.get("board")
        self._faults = getattr(kwargs.get("ctx"), "faults", None)
        super().setup(**kwargs)  # type: ignore[misc]

    def start_scope(self) -> None:
        """Clear this node's scope, if it starts one: called as it starts (from its
        ``initialise`` or its tick, never from py_trees' eager ``self.tick()`` calls)."""
        if self.scope is not None and self._board is not None:
            self._board.clear_scope(self.scope)

    def stop(self, new_status: py_trees.common.Status = py_trees.common.Status.INVALID) -> None:
        trace = self._trace
        if trace is not None:
            trace.acting.append(self)  # type: ignore[arg-type]
        try:
            quiet = _QUIET.get(type(self))
            if quiet is None:
                quiet = _QUIET[type(self)] = _quiet_stop(type(self))
            if quiet is _loud or py_trees.logging.level < py_trees.logging.Level.INFO:
                super().stop(new_status)  # type: ignore[misc]
            else:
                quiet(self, new_status)
        except Exception as exc:
            faults = self._faults
            if faults is None:
                raise
            faults.failed(getattr(self, "name", type(self).__name__), exc, "its terminate")
            self.status = new_status  # stopped all the same
            self.iterator = self.tick()  # type: ignore[attr-defined]
        finally:
            if trace is not None:
                trace.acting.pop()
        log = self.stop_log
        if log is not None:
            log.append(self)  # type: ignore[arg-type]


INVALID = py_trees.common.Status.INVALID
RUNNING = py_trees.common.Status.RUNNING


def _behaviour_stop(node: Any, new_status: py_trees.common.Status) -> None:
    """py_trees' ``Behaviour.stop``, but for its debug message."""
    node.terminate(new_status)
    node.status = new_status
    node.iterator = node.tick()


def _composite_stop(node: Any, new_status: py_trees.common.Status) -> None:
    """py_trees' ``Composite.stop`` (and ``Sequence``'s and ``Selector``'s, which log and
    call it), but for its debug message."""
    if new_status == INVALID:
        node.current_child = None
        for child in node.children:
            if child.status != INVALID:
                child.stop(new_status)
    node.terminate(new_status)
    node.status = new_status
    node.iterator = node.tick()


def _parallel_stop(node: Any, new_status: py_trees.common.Status) -> None:
    """py_trees' ``Parallel.stop``, but for its debug message."""
    for child in node.children:
        if child.status == RUNNING:
            child.stop(INVALID)
    _composite_stop(node, new_status)


def _decorator_stop(node: Any, new_status: py_trees.common.Status) -> None:
    """py_trees' ``Decorator.stop``, but for its debug message."""
    node.terminate(new_status)
    if new_status == INVALID:
        node.decorated.stop(new_status)
    if node.decorated.status == RUNNING:
        node.decorated.stop(INVALID)
    node.status = new_status


def _loud(node: Any, new_status: py_trees.common.Status) -> None:
    raise AssertionError("a marker: py_trees' own stop runs")


# py_trees' stops, each with the same calls in the same order but for the debug message
# it formats whether debug logging is on or not (half the time verify spends stopping)
_PY_TREES_STOPS: dict[Any, Any] = {
    py_trees.behaviour.Behaviour.stop: _behaviour_stop,
    py_trees.composites.Composite.stop: _composite_stop,
    py_trees.composites.Sequence.stop: _composite_stop,
    py_trees.composites.Selector.stop: _composite_stop,
    py_trees.composites.Parallel.stop: _parallel_stop,
    py_trees.decorators.Decorator.stop: _decorator_stop,
}
_QUIET: dict[type, Any] = {}


def _quiet_stop(cls: type) -> Any:
    """The quiet equal of the py_trees ``stop`` that ``super().stop`` reaches from
    :meth:`Observed.stop` in ``cls``, or :func:`_loud` when that is no stop of py_trees'
    own known here (then py_trees' runs)."""
    mro = cls.__mro__
    for base in mro[mro.index(Observed) + 1 :]:
        if "stop" in base.__dict__:
            return _PY_TREES_STOPS.get(base.__dict__["stop"], _loud)
    return _loud


def attach(root: Behaviour, log: list[Behaviour]) -> None:
    """Report every stop in the tree under ``root`` to ``log``; TypeError for a node that
    cannot report (a tree not built by the loader)."""
    for node in root.iterate():
        if not isinstance(node, Observed):
            raise TypeError(
                f"{node.name}: {type(node).__name__} is not an observed frog-bt node type"
            )
        node.stop_log = log
