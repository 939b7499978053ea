"""Every status change of a frog-bt tree, seen without patching py_trees.

py_trees changes a node's status in two places: in its ``tick`` (the tick
yields every node it reaches) and in its ``stop`` (which yields nothing). Every
node a tree file can build is one of our classes — leaves, decorators and the
composites below — and their ``stop`` reports the node to ``stop_log`` when one
is attached (:class:`~frog_bt.runtime.core.Core` attaches its own). Observers such as
telemetry then follow the tree in O(active path), not O(tree).
"""

from __future__ import annotations

import py_trees

Behaviour = py_trees.behaviour.Behaviour

# The frog-bt nodes whose tick (or stop) is running, innermost last: a command sent now
# is the last one's doing (blame, in recordings and replay). A tick runs to its end
# synchronously, so the stack is balanced between ticks.
ACTING: list[Behaviour] = []


# The frog-bt nodes with blackboard reads that ended (SUCCESS or FAILURE) in the current
# tick, in order: what decided a command sent later in the same tick (blame's reads).
# The core clears it before each tick.
DECIDED: list[Behaviour] = []


def acting() -> Behaviour | None:
    """The innermost frog-bt node ticking or stopping now, if any."""
    return ACTING[-1] if ACTING else None


class Observed:
    """Mixin (before the py_trees base): ``stop`` appends the node to ``stop_log``."""

    stop_log: list[Behaviour] | None = None

    def stop(self, new_status: py_trees.common.Status = py_trees.common.Status.INVALID
             ) -> None:
        ACTING.append(self)  # type: ignore[arg-type]
        try:
            super().stop(new_status)  # type: ignore[misc]
        finally:
            ACTING.pop()
        log = self.stop_log
        if log is not None:
            log.append(self)  # type: ignore[arg-type]


class Sequence(Observed, py_trees.composites.Sequence):
    """py_trees' Sequence, observed."""


class Selector(Observed, py_trees.composites.Selector):
    """py_trees' Selector, observed."""


class Parallel(Observed, py_trees.composites.Parallel):
    """py_trees' Parallel, observed."""


def attach(root: Behaviour, log: list[Behaviour]) -> None:
    """Report every stop in the tree under ``root`` to ``log``; TypeError for a node that
    cannot report (a tree not built by the loader)."""
    for node in root.iterate():
        if not isinstance(node, Observed):
            raise TypeError(f"{node.name}: {type(node).__name__} is not an observed frog-bt "
                            "node type")
        node.stop_log = log

