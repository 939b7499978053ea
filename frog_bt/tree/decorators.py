"""Decorators that keep time on the project clock (py_trees' own ``Timeout`` reads the wall clock).

* :class:`Retry` — runs its child again after FAILURE, up to ``attempts`` runs in
  all (``None``: until it succeeds); the child starts afresh each time.
* :class:`Timeout` — FAILURE (and the child stopped) once ``seconds`` of
  project-clock time have passed while the child is RUNNING.
* :class:`FaceStream` — a scope: ``/ICL_command`` ``start`` when entered, ``stop``
  when left for any reason (success, failure or interruption). Writes ``/icl``.

Every decorator declares a pydantic ``Params`` model like a leaf does, so tree
files are checked the same way.
"""

from __future__ import annotations

from typing import Any, ClassVar

import py_trees
from pydantic import BaseModel, Field

from frog_bt.context import Context
from frog_bt.tree.leaf import FAILURE, RUNNING, Params, Status


class _ClockDecorator(py_trees.decorators.Decorator):
    Params: ClassVar[type[BaseModel]] = Params
    reads: ClassVar[tuple[str, ...]] = ()
    writes: ClassVar[tuple[str, ...]] = ()

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour,
                 params: BaseModel | None = None) -> None:
        super().__init__(name=name, child=child)
        self.params: Any = params if params is not None else type(self).Params()
        self._ctx: Context | None = None

    def setup(self, **kwargs: Any) -> None:
        self._ctx = kwargs["ctx"]

    @property
    def ctx(self) -> Context:
        if self._ctx is None:
            raise RuntimeError(f"{self.name}: ticked before setup(ctx=...)")
        return self._ctx

    def describe(self) -> dict[str, Any]:
        return self.params.model_dump(exclude_none=True)


class Retry(_ClockDecorator):
    """Run the child again after FAILURE, up to ``attempts`` runs in all (None: forever).

    Returns the child's SUCCESS; RUNNING while retrying; FAILURE once the last
    attempt failed. Reads and writes nothing.
    """

    class Params(Params):
        attempts: int | None = Field(None, ge=1)

    def initialise(self) -> None:
        self.failures = 0

    def update(self) -> Status:
        status = self.decorated.status
        if status != FAILURE:
            return status
        self.failures += 1
        if self.params.attempts is not None and self.failures >= self.params.attempts:
            self.feedback_message = f"failed {self.failures} times"
            return FAILURE
        self.feedback_message = f"attempt {self.failures + 1}"
        return RUNNING


class Timeout(_ClockDecorator):
    """FAILURE once ``seconds`` of project-clock time pass with the child RUNNING.

    Otherwise returns the child's status. Reads and writes nothing.
    """

    class Params(Params):
        seconds: float = Field(gt=0, allow_inf_nan=False)

    def initialise(self) -> None:
        self.deadline = self.ctx.clock.now() + self.params.seconds

    def update(self) -> Status:
        status = self.decorated.status
        if status == RUNNING and self.ctx.clock.now() >= self.deadline:
            self.feedback_message = f"timed out after {self.params.seconds:g} s"
            self.ctx.note(f"{self.name}: {self.feedback_message}")
            return FAILURE
        return status


class FaceStream(_ClockDecorator):
    """Face data stream on while the child runs: ``/ICL_command`` start on entry, stop on exit.

    Writes ``/icl`` (True while the stream is on). Returns the child's status.
    """

    writes = ("/icl",)

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour,
                 params: BaseModel | None = None) -> None:
        super().__init__(name, child, params)
        self.bb = self.attach_blackboard_client(name=name)
        self.bb.register_key("/icl", access=py_trees.common.Access.WRITE)
        self.bb.set("/icl", False, overwrite=False)
        self._on = False

    def initialise(self) -> None:
        self.ctx.actions.icl(True)
        self._on = True
        self.bb.set("/icl", True, overwrite=True)

    def update(self) -> Status:
        return self.decorated.status

    def terminate(self, new_status: Status) -> None:
        if self._on:  # idempotent: py_trees may call terminate twice
            self._on = False
            self.ctx.actions.icl(False)
            self.bb.set("/icl", False, overwrite=True)


DECORATORS: dict[str, type[_ClockDecorator]] = {
    cls.__name__: cls for cls in (Retry, Timeout, FaceStream)
}
