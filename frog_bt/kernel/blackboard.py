"""Inputs cache and the pre-tick snapshot onto the py_trees blackboard.

Subscriber callbacks only *cache* (:class:`Inputs`); once per tick,
:meth:`Snapshot.write` copies one consistent view onto the blackboard, so no
input can change half-way through a tick (the py_trees_ros pattern).

Blackboard keys written here (the *input keys*; leaves declare what they read).
Each ROS input of the wire table (:data:`frog_bt.wire.INPUTS`) writes its key as
its :class:`~frog_bt.wire.Keep` says; with the default table:

============================  ===========================================================
``/now``                      project-clock time of this tick (s)
``/pose``                     :class:`Reading` of :class:`~frog_bt.rosbridge.msgs.Pose`, or None
``/persons``                  :class:`Reading` of PersonDetections (camera), or None
``/people``                   :class:`Reading` of TrackedPeople (laser), or None
``/faces``                    face samples received since the last tick: ``(t, Face)``
``/docking``                  :class:`Reading` of the docking state string, or None
``/diagnostics``              :class:`Reading` of Diagnostics, or None
``/responses``                ``/FROG_response`` codes since the last tick: ``(code, t)``
``/events``                   :class:`EventLog` of front-end events
``/frontend_ready``           a ``frontend_idle`` arrived since the last tour started/ended
``/link``                     rosbridge link state (anything with ``.connected``), or None
============================  ===========================================================
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import py_trees

from frog_bt.frontend.messages import FrontendIdle, FrontendMessage
from frog_bt.kernel.clock import Clock
from frog_bt.wire import INPUTS, Input, Keep

T = TypeVar("T")

FIXED_KEYS = ("/now", "/events", "/frontend_ready", "/link")


def peek(key: str) -> Any:
    """The value of ``key``, or None: py_trees' introspection read, for observers (status
    line, telemetry, summaries) that hold no blackboard client."""
    try:
        return py_trees.blackboard.Blackboard.get(key)
    except KeyError:
        return None


def input_keys() -> tuple[str, ...]:
    """Every key the snapshot writes (the fixed ones and the wire table's inputs)."""
    return (*FIXED_KEYS, *(inp.key for inp in INPUTS.values()))


@dataclass(frozen=True, slots=True)
class Reading(Generic[T]):
    """A value and the project-clock time it was received."""

    value: T
    at: float

    def age(self, now: float) -> float:
        return now - self.at


@dataclass(frozen=True, slots=True)
class Event:
    index: int
    at: float
    message: FrontendMessage


class EventLog:
    """Front-end events in arrival order, each with a growing index.

    A waiting leaf notes :attr:`last_index` when it starts and then looks only
    at newer events, so an event is never taken for an earlier request.
    """

    def __init__(self, maxlen: int = 256) -> None:
        self._events: deque[Event] = deque(maxlen=maxlen)
        self.last_index = 0

    def append(self, message: FrontendMessage, at: float) -> Event:
        self.last_index += 1
        event = Event(self.last_index, at, message)
        self._events.append(event)
        return event

    def __repr__(self) -> str:
        latest = ", ".join(e.message.type for e in list(self._events)[-3:])
        return f"{self.last_index} events, latest {latest or 'none'}"

    def since(self, index: int) -> Iterator[Event]:
        return (e for e in self._events if e.index > index)

    def first_since(self, index: int, type_: type[FrontendMessage], **fields: Any
                    ) -> Event | None:
        for event in self.since(index):
            msg = event.message
            if isinstance(msg, type_) and all(getattr(msg, k) == v for k, v in fields.items()):
                return event
        return None


class Inputs:
    """Latest inputs as the callbacks leave them; touched only by callbacks and snapshot.

    ``table`` maps each topic name to its :class:`~frog_bt.wire.Input`."""

    def __init__(self, table: dict[str, Input]) -> None:
        self.table = table
        self.latest: dict[str, Reading[Any] | None] = {
            i.key: None for i in table.values() if i.keep is Keep.LATEST}
        self.pending: dict[str, list[tuple[Any, Any]]] = {
            i.key: [] for i in table.values() if i.keep is not Keep.LATEST}
        self.link: Any = None
        self.events: list[tuple[FrontendMessage, float]] = []

    def add(self, inp: Input, value: Any, at: float) -> None:
        """Cache one decoded message of ``inp``."""
        if inp.keep is Keep.LATEST:
            self.latest[inp.key] = Reading(value, at)
            return
        pending = self.pending[inp.key]
        if inp.keep is Keep.SAMPLES:
            assert inp.items is not None
            pending.extend((at, item) for item in inp.items(value))
        else:
            pending.append((value, at))
        if len(pending) > inp.limit:
            del pending[: len(pending) - inp.limit]  # a stalled tick must not grow memory


class Snapshot:
    """Writes the input keys once per tick (the tree's pre-tick handler)."""

    def __init__(self, inputs: Inputs, clock: Clock) -> None:
        self.inputs = inputs
        self.clock = clock
        self.events = EventLog()
        self.bb = py_trees.blackboard.Client(name="snapshot")
        for key in (*FIXED_KEYS, *inputs.latest, *inputs.pending):
            self.bb.register_key(key, access=py_trees.common.Access.WRITE)
        self.bb.set("/frontend_ready", False)
        self.write()

    def write(self) -> None:
        inp = self.inputs
        set_ = self.bb.set
        set_("/now", self.clock.now())
        for key, reading in inp.latest.items():
            set_(key, reading)
        for key, pending in inp.pending.items():
            set_(key, tuple(pending))
            pending.clear()
        set_("/link", inp.link)
        if inp.events:
            for message, at in inp.events:
                self.events.append(message, at)
                if isinstance(message, FrontendIdle):
                    set_("/frontend_ready", True)
            inp.events.clear()
        set_("/events", self.events)

    def get(self, key: str) -> Any:
        return self.bb.get(key)
