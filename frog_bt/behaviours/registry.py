"""The tour's leaf and decorator types, in the order their modules define them:
``@register`` and ``@register_decorator`` add one."""

from __future__ import annotations

from typing import TypeVar

from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import Leaf

__all__ = ["DECORATOR_TYPES", "LEAF_TYPES", "register", "register_decorator"]

L = TypeVar("L", bound=type[Leaf])
D = TypeVar("D", bound=type[FrogDecorator])
LEAF_TYPES: list[type[Leaf]] = []
DECORATOR_TYPES: list[type[FrogDecorator]] = []


def register(cls: L) -> L:
    """Class decorator: a leaf type of the tour (see :data:`frog_bt.behaviours.FACTORY`)."""
    LEAF_TYPES.append(cls)
    return cls


def register_decorator(cls: D) -> D:
    """Class decorator: a decorator type of the tour (a scope: the face stream, ...)."""
    DECORATOR_TYPES.append(cls)
    return cls
