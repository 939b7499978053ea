"""The base class and registry of every leaf a tree file can name.

A leaf type declares its parameters (a pydantic model), the blackboard keys it
reads (``reads``: something must write them; ``optional_reads``: a default
applies while nothing has) and the keys it writes; :func:`register` adds it to :data:`LEAVES` under
its class name. The loader checks a whole tree file against these declarations
before anything connects, and ``render`` draws a tree with no robot.

Lifecycle (py_trees): ``__init__`` holds only what rendering needs; ``setup``
receives the run-time :class:`~frog_bt.context.Context`; ``initialise`` starts
work, ``update`` polls it and never blocks, ``terminate`` cancels it and may be
called twice.
"""

from __future__ import annotations

from typing import Any, ClassVar, TypeVar

import py_trees
from pydantic import BaseModel, ConfigDict

from frog_bt.context import Context

Status = py_trees.common.Status
SUCCESS, FAILURE, RUNNING, INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID


_BB = py_trees.blackboard.Blackboard


def direct_keys(client: py_trees.blackboard.Client, keys: tuple[str, ...]) -> frozenset[str]:
    """The keys of ``client`` that a plain dict access can serve: absolute and not remapped.

    py_trees' ``Client.get``/``set`` resolve the name and check access on every call
    (about 3 µs each, a large share of a tick). Access was checked when the key was
    registered, so while no activity stream is on a read or write of one of these keys
    is just ``Blackboard.storage[key]``; any other key takes py_trees' own path.
    """
    return frozenset(k for k in keys if client.remappings.get(k) == k)


class Params(BaseModel):
    """Base of every leaf's parameter model: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class Leaf(py_trees.behaviour.Behaviour):
    Params: ClassVar[type[BaseModel]] = Params
    reads: ClassVar[tuple[str, ...]] = ()  # must be written by some node or the snapshot
    optional_reads: ClassVar[tuple[str, ...]] = ()  # read when present, with a default
    writes: ClassVar[tuple[str, ...]] = ()

    def __init__(self, name: str, params: BaseModel | None = None) -> None:
        super().__init__(name)
        self.params: Any = params if params is not None else type(self).Params()
        self.bb = self.attach_blackboard_client(name=name)
        for key in (*self.reads, *self.optional_reads):
            self.bb.register_key(key, access=py_trees.common.Access.READ)
        for key in self.writes:
            self.bb.register_key(key, access=py_trees.common.Access.WRITE)
        self._direct_reads = direct_keys(self.bb, (*self.reads, *self.optional_reads,
                                                   *self.writes))
        self._direct_writes = direct_keys(self.bb, self.writes)
        self._ctx: Context | None = None

    def setup(self, **kwargs: Any) -> None:
        self._ctx = kwargs["ctx"]

    @property
    def ctx(self) -> Context:
        if self._ctx is None:
            raise RuntimeError(f"{self.name}: ticked before setup(ctx=...)")
        return self._ctx

    def get(self, key: str, default: Any = None) -> Any:
        """The blackboard value of ``key``, or ``default`` while nothing has written it."""
        if key in self._direct_reads and _BB.activity_stream is None:
            return _BB.storage.get(key, default)
        try:
            return self.bb.get(key)
        except KeyError:
            return default

    def set(self, key: str, value: Any) -> None:
        if key in self._direct_writes and _BB.activity_stream is None:
            _BB.storage[key] = value
        else:
            self.bb.set(key, value, overwrite=True)

    def describe(self) -> dict[str, Any]:
        """Parameters as shown by ``render`` (unset ones omitted)."""
        return self.params.model_dump(exclude_none=True)


L = TypeVar("L", bound=type[Leaf])
LEAVES: dict[str, type[Leaf]] = {}


def register(cls: L) -> L:
    if cls.__name__ in LEAVES:
        raise ValueError(f"leaf type {cls.__name__} registered twice")
    LEAVES[cls.__name__] = cls
    return cls
