"""The one way to walk a running tree: a node's children, its running child, the running
path from the root (the status line's phase, the console's "what the robot is doing",
telemetry).
"""

from __future__ import annotations

from collections.abc import Iterator

import py_trees

__all__ = ["children", "running_child", "running_path"]

Behaviour = py_trees.behaviour.Behaviour
Status = py_trees.common.Status


def children(node: Behaviour) -> list[Behaviour]:
    """A decorator's child, or a composite's children (none for a leaf)."""
    if isinstance(node, py_trees.decorators.Decorator):
        return [node.decorated]
    return list(node.children)


def running_child(node: Behaviour) -> Behaviour | None:
    """The child of ``node`` that runs now, if any. A sequence's or selector's is its
    ``current_child`` (no scan of its children: this runs after every tick when the console
    is on); a parallel's is the first of them that runs."""
    if isinstance(node, py_trees.decorators.Decorator):
        child: Behaviour | None = node.decorated
        return child if child is not None and child.status is Status.RUNNING else None
    if isinstance(node, py_trees.composites.Composite) and not isinstance(
        node, py_trees.composites.Parallel
    ):
        child = node.current_child
        if child is not None and child.status is Status.RUNNING:
            return child
    return next((c for c in node.children if c.status is Status.RUNNING), None)


def running_path(root: Behaviour) -> Iterator[Behaviour]:
    """The root, then each running child down to the innermost running node."""
    node: Behaviour | None = root
    while node is not None:
        yield node
        node = running_child(node)
