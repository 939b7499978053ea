"""The base class of every leaf a tree file can name.

A leaf type declares its parameters and blackboard keys
(:class:`~frog_bt.tree.node.Declared`); a :class:`~frog_bt.tree.factory.NodeFactory`
registers it under its class name. The loader checks a whole tree file
against these declarations before anything connects, and ``render`` draws a
tree with no robot.

Lifecycle (py_trees): ``__init__`` holds only what rendering needs; ``setup``
receives the run-time :class:`~frog_bt.engine.context.Context`; ``initialise`` starts
work, ``update`` polls it and never blocks, ``terminate`` cancels it and may be
called twice.
"""

from __future__ import annotations

from pydantic import BaseModel

from frog_bt.engine.lean import LeanBehaviour
from frog_bt.engine.observed import Observed
from frog_bt.tree.node import (
    FAILURE,
    INVALID,
    RUNNING,
    SUCCESS,
    Declared,
    Params,
    Status,
)

__all__ = ["FAILURE", "INVALID", "RUNNING", "SUCCESS", "Leaf", "Params", "Status"]


class Leaf(Observed, Declared, LeanBehaviour):
    def __init__(self, name: str, params: BaseModel | None = None) -> None:
        super().__init__(name)
        self._declare(params)
