"""What every frog-bt leaf and decorator declares and reaches.

A node type declares its parameters (``Params``, a pydantic model: unknown keys
are errors), the blackboard keys it reads (``reads``: something must write them;
``optional_reads``: a default applies while nothing has) and the keys it writes.
The loader checks a whole tree against these declarations before anything
connects. At run time ``setup`` hands the node the
:class:`~frog_bt.runtime.context.Context`; :meth:`Declared.get` and :meth:`Declared.set`
reach the blackboard.
"""

from __future__ import annotations

from typing import Any, ClassVar

import py_trees
from pydantic import BaseModel, ConfigDict

from frog_bt.runtime.context import Context

Status = py_trees.common.Status
SUCCESS, FAILURE, RUNNING, INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID


class Params(BaseModel):
    """Base of every node's parameter model: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class Declared:
    """Mixin for py_trees behaviours: declared parameters and keys, context, blackboard."""

    Params: ClassVar[type[BaseModel]] = Params
    reads: ClassVar[tuple[str, ...]] = ()
    optional_reads: ClassVar[tuple[str, ...]] = ()
    writes: ClassVar[tuple[str, ...]] = ()
    name: str

    def _declare(self, params: BaseModel | None) -> None:
        """Call from ``__init__`` once the py_trees base is initialised."""
        self.params: Any = params if params is not None else type(self).Params()
        self._ctx: Context | None = None
        if self.reads or self.optional_reads or self.writes:
            self.bb = self.attach_blackboard_client(name=self.name)  # type: ignore[attr-defined]
            for key in (*self.reads, *self.optional_reads):
                self.bb.register_key(key, access=py_trees.common.Access.READ)
            for key in self.writes:
                self.bb.register_key(key, access=py_trees.common.Access.WRITE)

    def setup(self, **kwargs: Any) -> None:
        self._ctx = kwargs["ctx"]

    @property
    def ctx(self) -> Context:
        if self._ctx is None:
            raise RuntimeError(f"{self.name}: ticked before setup(ctx=...)")
        return self._ctx

    def get(self, key: str, default: Any = None) -> Any:
        """The blackboard value of ``key``, or ``default`` while nothing has written it."""
        try:
            return self.bb.get(key)
        except KeyError:
            return default

    def set(self, key: str, value: Any) -> None:
        self.bb.set(key, value, overwrite=True)

    def describe(self) -> dict[str, Any]:
        """Parameters as shown by ``render`` (unset ones omitted)."""
        return self.params.model_dump(exclude_none=True)
