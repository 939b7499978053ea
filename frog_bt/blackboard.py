"""Inputs cache and the pre-tick snapshot onto the py_trees blackboard.

Subscriber callbacks only *cache* (:class:`Inputs`); once per tick,
:meth:`Snapshot.write` copies one consistent view onto the blackboard, so no
input can change half-way through a tick (the py_trees_ros pattern).

Blackboard keys written here (the *input keys*; leaves declare what they read):

============================  ===========================================================
``/now``                      project-clock time of this tick (s)
``/pose``                     :class:`Reading` of :class:`~frog_bt.messages.Pose`, or None
``/persons``                  :class:`Reading` of PersonDetections (camera), or None
``/people``                   :class:`Reading` of TrackedPeople (laser), or None
``/faces``                    face samples received since the last tick: ``(t, Face)``
``/docking``                  :class:`Reading` of the docking state string, or None
``/diagnostics``              :class:`Reading` of Diagnostics, or None
``/events``                   :class:`EventLog` of front-end events
``/frontend_ready``           a ``frontend_idle`` arrived since the last tour started/ended
``/link``                     rosbridge link state (anything with ``.connected``), or None
============================  ===========================================================
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, Generic, TypeVar

import py_trees

from frog_bt.actions import Actions
from frog_bt.clock import Clock
from frog_bt.frontend.messages import FrontendIdle, FrontendMessage
from frog_bt.messages import Diagnostics, Face, FaceData, PersonDetections, Pose, TrackedPeople

T = TypeVar("T")

INPUT_KEYS = ("/now", "/pose", "/persons", "/people", "/faces", "/docking", "/diagnostics",
              "/events", "/frontend_ready", "/link")


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

    def since(self, index: int) -> Iterator[Event]:
        return (e for e in self._events if e.index > index)

    def first_since(self, index: int, type_: type[FrontendMessage], **fields: Any
                    ) -> Event | None:
        for event in self.since(index):
            msg = event.message
            if isinstance(msg, type_) and all(getattr(msg, k) == v for k, v in fields.items()):
                return event
        return None


@dataclass(slots=True)
class Inputs:
    """Latest inputs as the callbacks leave them; touched only by callbacks and snapshot."""

    pose: Reading[Pose] | None = None
    persons: Reading[PersonDetections] | None = None
    people: Reading[TrackedPeople] | None = None
    docking: Reading[str] | None = None
    diagnostics: Reading[Diagnostics] | None = None
    link: Any = None
    faces: list[tuple[float, Face]] = field(default_factory=list)
    responses: list[tuple[int, float]] = field(default_factory=list)
    events: list[tuple[FrontendMessage, float]] = field(default_factory=list)
    face_limit: int = 10_000

    def add_faces(self, data: FaceData, at: float) -> None:
        if len(self.faces) + len(data.faces) > self.face_limit:
            del self.faces[: len(data.faces)]  # a stalled tick must not grow memory
        self.faces.extend((at, f) for f in data.faces)


class Snapshot:
    """Writes the input keys once per tick (the tree's pre-tick handler)."""

    def __init__(self, inputs: Inputs, clock: Clock, actions: Actions) -> None:
        self.inputs = inputs
        self.clock = clock
        self.actions = actions
        self.events = EventLog()
        self.bb = py_trees.blackboard.Client(name="snapshot")
        for key in INPUT_KEYS:
            self.bb.register_key(key, access=py_trees.common.Access.WRITE)
        self.bb.set("/frontend_ready", False)
        self.bb.set("/faces", ())
        self.write()

    def write(self) -> None:
        inp = self.inputs
        if py_trees.blackboard.Blackboard.activity_stream is not None:
            set_ = self.bb.set  # py_trees' own path, so that the stream sees every write
        else:
            # The keys were registered for writing in __init__; a client's set() would
            # check that again, ten times a tick (~3 µs each).
            set_ = py_trees.blackboard.Blackboard.storage.__setitem__
        set_("/now", self.clock.now())
        set_("/pose", inp.pose)
        set_("/persons", inp.persons)
        set_("/people", inp.people)
        set_("/docking", inp.docking)
        set_("/diagnostics", inp.diagnostics)
        set_("/link", inp.link)
        if inp.faces:
            set_("/faces", tuple(inp.faces))
            inp.faces.clear()
        else:
            set_("/faces", ())
        if inp.responses:
            for code, at in inp.responses:
                self.actions.on_response(code, at)
            inp.responses.clear()
        if inp.events:
            for message, at in inp.events:
                self.events.append(message, at)
                if isinstance(message, FrontendIdle):
                    set_("/frontend_ready", True)
            inp.events.clear()
        set_("/events", self.events)
