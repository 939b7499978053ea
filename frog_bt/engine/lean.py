"""py_trees' ticks for frog-bt's nodes, without the work they do for a debug log.

py_trees 2.6's ``tick`` of a behaviour, a decorator, a sequence and a selector formats
a debug message on every call (``f"{self.__class__.__name__}.tick()"``, built whether
or not anything logs it) and checks the status ``update`` returned against
``list(common.Status)``, a list built from the enum each time. Across the ~90 nodes
that the tick starting a tour passes through, that is about a third of the tick's
time. The classes here give the same ticks — statement for statement py_trees' own,
which the verify explorer and the tests hold to — with the status checked against a
tuple made once, and py_trees' own tick when its debug logging is on (as
:mod:`frog_bt.engine.observed` does for ``stop``).

They sit just above py_trees' classes in frog-bt's nodes' bases
(``Leaf(Observed, Declared, LeanBehaviour)``, ...), so that a node's own ``tick`` and
:class:`~frog_bt.tree.node.Declared`'s wrapper still come first.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import py_trees
from py_trees import common

Behaviour = py_trees.behaviour.Behaviour
Status = common.Status
RUNNING, SUCCESS, FAILURE, INVALID = Status.RUNNING, Status.SUCCESS, Status.FAILURE, Status.INVALID
STATUSES = tuple(Status)
_DEBUG = py_trees.logging.Level.DEBUG


def _debugging() -> bool:
    """Is py_trees' own debug logging on (then its ticks run, with their messages)?"""
    return py_trees.logging.level <= _DEBUG


def _checked(node: Behaviour, new_status: Status) -> Status:
    if new_status not in STATUSES:
        node.logger.error(
            "A behaviour returned an invalid status, setting to INVALID "
            f"[{new_status}][{node.name}]"
        )
        return INVALID
    return new_status


def _update(node: Behaviour) -> None:
    """The end of a behaviour's or a decorator's tick: ``update``, checked; stopped when
    it is not RUNNING; the status set."""
    new_status = _checked(node, node.update())
    if new_status != RUNNING:
        node.stop(new_status)
    node.status = new_status


class LeanBehaviour(Behaviour):
    """py_trees' ``Behaviour.tick``, lean."""

    def tick(self) -> Iterator[Behaviour]:
        if _debugging():
            yield from super().tick()
            return
        if self.status != RUNNING:
            self.initialise()
        _update(self)
        yield self


class LeanDecorator(py_trees.decorators.Decorator):
    """py_trees' ``Decorator.tick``, lean."""

    def tick(self) -> Iterator[Behaviour]:
        if _debugging():
            yield from super().tick()
            return
        if self.status != RUNNING:
            self.initialise()
        yield from self.decorated.tick()
        _update(self)
        yield self


class LeanSequence(py_trees.composites.Sequence):
    """py_trees' ``Sequence.tick``, lean."""

    def tick(self) -> Iterator[Behaviour]:
        if _debugging():
            yield from super().tick()
            return
        children = self.children
        index = 0
        if self.status != RUNNING:
            self.current_child = children[0] if children else None
            for child in children:
                if child.status != INVALID:
                    child.stop(INVALID)
            self.initialise()
        elif self.memory and self.current_child is not None:
            index = children.index(self.current_child)
        else:
            self.current_child = children[0] if children else None
        if not children:
            self.current_child = None
            self.stop(SUCCESS)
            yield self
            return
        for child in itertools.islice(children, index, None):
            for node in child.tick():
                yield node
                if node is child and node.status != SUCCESS:
                    if not self.memory:  # invalidate the rest: dangling runners
                        for later in itertools.islice(children, index + 1, None):
                            if later.status != INVALID:
                                later.stop(INVALID)
                    if node.status != RUNNING:
                        self.stop(node.status)
                    else:
                        self.status = node.status
                    yield self
                    return
            if index + 1 < len(children):
                self.current_child = children[index + 1]
                index += 1
        self.stop(SUCCESS)
        yield self


class LeanSelector(py_trees.composites.Selector):
    """py_trees' ``Selector.tick``, lean."""

    def tick(self) -> Iterator[Behaviour]:
        if _debugging():
            yield from super().tick()
            return
        children = self.children
        if self.status != RUNNING:
            self.current_child = children[0] if children else None
            self.initialise()
        if not children:
            self.current_child = None
            self.stop(FAILURE)
            yield self
            return
        if self.memory:
            assert self.current_child is not None
            index = children.index(self.current_child)
            for child in itertools.islice(children, None, index):
                if child.status != INVALID:
                    child.stop(INVALID)
        else:
            index = 0
        previous = self.current_child
        for child in itertools.islice(children, index, None):
            for node in child.tick():
                yield node
                if node is child and (node.status == RUNNING or node.status == SUCCESS):
                    self.current_child = child
                    if previous is None or previous != self.current_child:
                        # interrupted: invalidate everything at a lower priority
                        passed = False
                        for other in children:
                            if passed and other.status != INVALID:
                                other.stop(INVALID)
                            passed = True if other == self.current_child else passed
                    if node.status == SUCCESS:
                        self.stop(node.status)
                    else:
                        self.status = node.status
                    yield self
                    return
        self.stop(FAILURE)
        self.current_child = children[-1] if children else None
        yield self
