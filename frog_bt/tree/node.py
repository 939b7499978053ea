"""What every frog-bt leaf and decorator declares and reaches.

A node type declares its parameters (``Params``, a pydantic model: unknown keys
are errors) and the typed keys (:mod:`frog_bt.model.keys`) it reads (``reads``:
something must write them before; ``optional_reads``: None while nothing has) and
writes. The loader checks a whole tree against these declarations before anything
connects. At run time ``setup`` hands the node the
:class:`~frog_bt.engine.context.Context` (services), the core's board and trace;
:meth:`Declared.get` and :meth:`Declared.set` reach the board, for declared keys only.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, TypeVar

import py_trees
from pydantic import BaseModel, ConfigDict

from frog_bt.engine.context import Context
from frog_bt.model.key import Key, Readable, Source
from frog_bt.model.outcomes import IncidentKind

if TYPE_CHECKING:
    from frog_bt.engine.blackboard import Board
    from frog_bt.engine.observed import Trace

Status = py_trees.common.Status
SUCCESS, FAILURE, RUNNING, INVALID = Status.SUCCESS, Status.FAILURE, Status.RUNNING, Status.INVALID
ENDED = frozenset((SUCCESS, FAILURE))
T = TypeVar("T")


class MissingValue(Exception):
    """A required key a tree node writes has no value yet (the tree was built wrong
    past the load-time check): the reading node fails with this reason."""

    def __init__(self, key: Readable[Any]) -> None:
        super().__init__(key.name)
        self.key = key


class Params(BaseModel):
    """Base of every node's parameter model: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class NodeParams(Protocol):
    """What the base reads of a node's parameters (an instance of its ``Params``). A node
    type that reads their fields declares ``params: Params`` in its class body, and the
    checker holds ``self.params.poi``; a base may ask more of its subclasses' ``Params``
    with a protocol of its own (``GoalLeaf``: a ``timeout``)."""

    def model_dump(self, *, exclude_none: bool = ...) -> dict[str, Any]: ...


class Declared:
    """Mixin for py_trees behaviours: declared parameters and keys, context, board."""

    Params: ClassVar[type[BaseModel]] = Params
    params: NodeParams
    reads: ClassVar[tuple[Key[Any], ...]] = ()
    optional_reads: ClassVar[tuple[Key[Any], ...]] = ()
    writes: ClassVar[tuple[Key[Any], ...]] = ()
    name: str

    def _declare(self, params: BaseModel | None) -> None:
        """Call from ``__init__`` once the py_trees base is initialised."""
        self._reads_any = bool(self.reads or self.optional_reads)  # blame: a decider
        self.params = params if params is not None else type(self).Params()
        self._ctx: Context | None = None
        self._bb: Board | None = None
        self._trace_: Trace | None = None
        self._readable = frozenset((*self.reads, *self.optional_reads, *self.writes))
        self._writable = frozenset(self.writes)
        self._required = frozenset(k for k in self.reads if k.source is Source.LEAF)

    def setup(self, **kwargs: Any) -> None:
        self._ctx = kwargs["ctx"]
        self._bb = kwargs["board"]
        self._trace_ = kwargs["trace"]

    @property
    def ctx(self) -> Context:
        if self._ctx is None:
            raise RuntimeError(f"{self.name}: ticked before setup(ctx=...)")
        return self._ctx

    def get(self, key: Readable[T]) -> T | None:
        """The board's value of ``key`` (declared in ``reads``, ``optional_reads`` or
        ``writes``), None while nothing has written it.

        A required read (``reads``) of a key that tree nodes write, and that none has
        written in this scope, fails the node with the reason in its feedback (inputs
        may be None: no data yet, which the leaves handle)."""
        if key not in self._readable:
            raise KeyError(f"{self.name} reads {key.name} without declaring it")
        board = self._bb
        assert board is not None, "get() before setup()"
        value = board.get(key)
        if value is None and key in self._required and not board.written(key):
            raise MissingValue(key)
        return value

    def need(self, key: Readable[T]) -> T:
        """:meth:`get` for a key the snapshot always writes (``/now``, ``/events``)."""
        value = self.get(key)
        assert value is not None, f"{key.name} is written before every tick"
        return value

    def set(self, key: Key[T], value: T | None) -> None:
        if key not in self._writable:
            raise KeyError(f"{self.name} writes {key.name} without declaring it")
        assert self._bb is not None, "set() before setup()"
        self._bb.set(key, value)

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        trace = self._trace_
        assert trace is not None, "ticked before setup(trace=...)"
        trace.acting.append(self)  # type: ignore[arg-type]
        try:
            if self.status != RUNNING:  # type: ignore[attr-defined]
                self.start_scope()  # type: ignore[attr-defined]
            yield from super().tick()  # type: ignore[misc]
            if self._reads_any and self.status in ENDED:  # type: ignore[attr-defined]
                trace.decided.append(self)  # type: ignore[arg-type]
        except MissingValue as missing:
            self.feedback_message = f"no value for {missing.key.name}"
            self.ctx.note(
                f"{self.name}: no value for {missing.key.name}; failing",
                incident=IncidentKind.MISSING_VALUE,
                subject=missing.key.name,
            )
            self.stop(FAILURE)  # type: ignore[attr-defined]
            yield self  # type: ignore[misc]
        except Exception as exc:
            faults = self._ctx.faults if self._ctx is not None else None
            if faults is None:
                raise
            seen = faults.failed(self.name, exc, "its tick")
            self.feedback_message = f"failed: {seen.error}"
            with contextlib.suppress(Exception):  # its terminate is counted by Observed.stop
                self.stop(FAILURE)  # type: ignore[attr-defined]
            # the tick that failed counts as the node's failure (py_trees' own attribute)
            setattr(self, "status", FAILURE)  # noqa: B010
            yield self  # type: ignore[misc]
        finally:
            trace.acting.pop()

    def describe(self) -> dict[str, Any]:
        """Parameters as shown by ``render`` (unset ones omitted)."""
        return self.params.model_dump(exclude_none=True)
