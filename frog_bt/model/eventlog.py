"""The front end's events as the tree sees them: one log, each event with a growing index."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from frog_bt.model.frontend import FrontendMessage


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

    def first_since(self, index: int, type_: type[FrontendMessage], **fields: Any) -> Event | None:
        for event in self.since(index):
            msg = event.message
            if isinstance(msg, type_) and all(getattr(msg, k) == v for k, v in fields.items()):
                return event
        return None
