"""What every frog-bt leaf and decorator declares and reaches.

A node type declares its parameters (``Params``, a pydantic model: unknown keys
are errors), the blackboard keys it reads (``reads``: something must write them;
``optional_reads``: a default applies while nothing has) and the keys it writes.
The loader checks a whole tree against these declarations before anything
connects. At run time ``setup`` hands the node the
:class:`~frog_bt.kernel.context.Context`; :meth:`Declared.get` and :meth:`Declared.set`
reach the blackboard.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, ClassVar

import py_trees
from pydantic import BaseModel, ConfigDict

from frog_bt.kernel.context import Context
from frog_bt.tree.observed import ACTING, DECIDED

Status = py_trees.common.Status
SUCCESS, FAILURE, RUNNING, INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID
ENDED = frozenset((SUCCESS, FAILURE))


class MissingValue(Exception):
    """A required key a tree node writes has no value yet (the tree was built wrong
    past the load-time check): the reading node fails with this reason."""

    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key


class Params(BaseModel):
    """Base of every node's parameter model: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class Declared:
    """Mixin for py_trees behaviours: declared parameters and keys, context, blackboard."""

    Params: ClassVar[type[BaseModel]] = Params
    reads: ClassVar[tuple[str, ...]] = ()
    optional_reads: ClassVar[tuple[str, ...]] = ()
    writes: ClassVar[tuple[str, ...]] = ()
    key_types: ClassVar[dict[str, Any]] = {}  # key -> the type this node takes it as
    name: str

    def _declare(self, params: BaseModel | None) -> None:
        """Call from ``__init__`` once the py_trees base is initialised."""
        self._reads_any = bool(self.reads or self.optional_reads)  # blame: a decider
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
        """The blackboard value of ``key``, or ``default`` while nothing has written it.

        A required read (``reads``) of a key that tree nodes write never returns None:
        the node then FAILs with the reason in its feedback (inputs may be None: no
        data yet, which the leaves handle)."""
        try:
            value = self.bb.get(key)
        except KeyError:
            value = default
        if value is None and key in self.reads and key not in _input_keys():
            raise MissingValue(key)
        return value

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        ACTING.append(self)  # type: ignore[arg-type]
        try:
            yield from super().tick()  # type: ignore[misc]
            if self._reads_any and self.status in ENDED:  # type: ignore[attr-defined]
                DECIDED.append(self)  # type: ignore[arg-type]
        except MissingValue as missing:
            self.feedback_message = f"no value for {missing.key}"  # type: ignore[attr-defined]
            self.ctx.note(f"{self.name}: no value for {missing.key}; failing",
                          incident="missing value", subject=missing.key)
            self.stop(FAILURE)  # type: ignore[attr-defined]
            yield self  # type: ignore[misc]
        finally:
            ACTING.pop()

    def set(self, key: str, value: Any) -> None:
        self.bb.set(key, value, overwrite=True)

    def describe(self) -> dict[str, Any]:
        """Parameters as shown by ``render`` (unset ones omitted)."""
        return self.params.model_dump(exclude_none=True)


def _input_keys() -> frozenset[str]:
    from frog_bt.kernel.blackboard import input_keys  # the runtime imports the tree

    return frozenset(input_keys())
