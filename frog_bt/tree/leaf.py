"""The base class and registry of every leaf a tree file can name.

A leaf type declares its parameters and blackboard keys
(:class:`~frog_bt.tree.node.Declared`); :func:`register` adds it to
:data:`LEAVES` under its class name. The loader checks a whole tree file
against these declarations before anything connects, and ``render`` draws a
tree with no robot.

Lifecycle (py_trees): ``__init__`` holds only what rendering needs; ``setup``
receives the run-time :class:`~frog_bt.kernel.context.Context`; ``initialise`` starts
work, ``update`` polls it and never blocks, ``terminate`` cancels it and may be
called twice.
"""

from __future__ import annotations

from typing import TypeVar

import py_trees
from pydantic import BaseModel

from frog_bt.tree.node import (
    FAILURE,
    INVALID,
    RUNNING,
    SUCCESS,
    Declared,
    Params,
    Status,
)
from frog_bt.tree.observed import Observed

__all__ = ["FAILURE", "INVALID", "LEAVES", "RUNNING", "SUCCESS", "Leaf", "Params", "Status",
           "register"]


class Leaf(Observed, Declared, py_trees.behaviour.Behaviour):
    def __init__(self, name: str, params: BaseModel | None = None) -> None:
        super().__init__(name)
        self._declare(params)


L = TypeVar("L", bound=type[Leaf])
LEAVES: dict[str, type[Leaf]] = {}


def register(cls: L) -> L:
    if cls.__name__ in LEAVES:
        raise ValueError(f"leaf type {cls.__name__} registered twice")
    LEAVES[cls.__name__] = cls
    return cls
