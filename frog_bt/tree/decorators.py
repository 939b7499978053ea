"""Decorators of tour trees, and the project-clock ones every tree may use.

A decorator declares parameters and blackboard keys like a leaf does (see
:mod:`frog_bt.tree.leaf`); tree files name it by class name. The ones below are every
tree's (:data:`DECORATORS`, which every :class:`~frog_bt.tree.factory.NodeFactory`
starts with); a domain scope is registered into a factory.

* :class:`Retry` — runs its child again after FAILURE, up to ``attempts`` runs in
  all (``None``: until it succeeds); the child starts afresh each time.
* :class:`Timeout` — FAILURE (and the child stopped) once ``seconds`` of
  project-clock time have passed while the child is RUNNING. (py_trees' own
  ``Timeout`` reads the wall clock.)
* :class:`FailureIsSuccess` — an optional part: its child's FAILURE is SUCCESS.

Domain scopes (face stream, projector, follow-me, location) live with their
behaviours in :mod:`frog_bt.behaviours`.
"""

from __future__ import annotations

import math
from typing import Any, TypeVar

import py_trees
from pydantic import BaseModel, Field

from frog_bt.engine.lean import LeanDecorator
from frog_bt.engine.observed import Observed
from frog_bt.tree.node import FAILURE, RUNNING, Declared, Params, Status
from frog_bt.tree.world import Channel, World


class FrogDecorator(Observed, Declared, LeanDecorator):
    """A decorator a tree file can name. One that is a py_trees decorator with our
    parameters lists that class among its bases and maps the parameters to its
    constructor's in :meth:`base_kwargs`."""

    def __init__(
        self, name: str, child: py_trees.behaviour.Behaviour, params: BaseModel | None = None
    ) -> None:
        params = params if params is not None else type(self).Params()
        super().__init__(name=name, child=child, **self.base_kwargs(params))
        self._declare(params)

    def base_kwargs(self, params: Any) -> dict[str, Any]:
        return {}


D = TypeVar("D", bound=type[FrogDecorator])
DECORATORS: dict[str, type[FrogDecorator]] = {}


def register_decorator(cls: D) -> D:
    """Class decorator: one of every tree's decorators (this module's own)."""
    if cls.__name__ in DECORATORS:
        raise ValueError(f"decorator type {cls.__name__} registered twice")
    DECORATORS[cls.__name__] = cls
    return cls


@register_decorator
class Retry(FrogDecorator, py_trees.decorators.Retry):
    """Run the child again after FAILURE, up to ``attempts`` runs in all (None: forever):
    py_trees' ``Retry``.

    Returns the child's SUCCESS; RUNNING while retrying (the child restarts on
    the next tick); FAILURE once the last attempt failed. Reads and writes nothing.
    """

    class Params(Params):
        attempts: int | None = Field(
            None, ge=1, description=("runs in all (null: until it succeeds)")
        )

    params: Params
    # an unbounded retry's count changes nothing it does: kept out of the state
    world = World(state=("failures",), key=lambda n: n.failures if n.params.attempts else 0)

    def base_kwargs(self, params: Any) -> dict[str, Any]:
        return {"num_failures": params.attempts or math.inf}

    def describe(self) -> dict[str, Any]:
        return {"attempts": self.params.attempts or "until success"}


@register_decorator
class Timeout(FrogDecorator):
    """FAILURE once ``seconds`` of project-clock time pass with the child RUNNING.

    Otherwise returns the child's status. Reads and writes nothing.
    """

    class Params(Params):
        seconds: float = Field(
            gt=0, allow_inf_nan=False, description=("project-clock seconds the child may run")
        )

    params: Params
    world = World(
        inputs=(Channel.CLOCK,),
        state=("deadline",),
        times=("deadline",),
        timer=lambda n: n.deadline,
    )

    def initialise(self) -> None:
        self.deadline = self.ctx.clock.now() + self.params.seconds

    def update(self) -> Status:
        status = self.decorated.status
        if status == RUNNING and self.ctx.clock.now() >= self.deadline:
            self.feedback_message = f"timed out after {self.params.seconds:g} s"
            self.ctx.note(f"{self.name}: {self.feedback_message}")
            return FAILURE
        return status


@register_decorator
class FailureIsSuccess(FrogDecorator, py_trees.decorators.FailureIsSuccess):
    """An optional part: SUCCESS when the child fails, else the child's status
    (py_trees' ``FailureIsSuccess``)."""

    child_may_fail = True  # nothing the child writes is sure after it (the data-flow check)
    world = World()
