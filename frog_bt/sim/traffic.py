"""The simulator's message log: every message it sends or receives, for tests.

Each :class:`Record` says when (simulated time), on which side (``ros`` or
``frontend``), which way (``in``: received by the simulator, i.e. sent by the
executive; ``out``: sent by the simulator), on which channel (ROS topic or
front-end message type, ``ack`` for acks) and the payload (the ROS ``msg``, or
the datagram's fields). ``/clock`` is not logged, nor are front-end resends
and duplicates; the log keeps the newest ``maxlen`` records.

:meth:`MessageLog.wait_for` is event-driven: tests wait for what they expect,
never for a fixed time.
"""

from __future__ import annotations

import asyncio
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, overload

Predicate = Callable[["Record"], bool]


@dataclass(frozen=True, slots=True)
class Record:
    t: float  # simulated time, seconds since the epoch
    side: str  # "ros" | "frontend"
    direction: str  # "in" (received by the simulator) | "out" (sent by it)
    channel: str  # ROS topic or front-end message type
    payload: Any

    def __str__(self) -> str:
        arrow = "->" if self.direction == "out" else "<-"
        return f"{self.t:.2f} {self.side:<8} {arrow} {self.channel} {self.payload}"


class MessageLog(Sequence[Record]):
    """A bounded, append-only sequence of :class:`Record` with waiters and listeners."""

    def __init__(self, maxlen: int = 200_000) -> None:
        self._records: deque[Record] = deque(maxlen=maxlen)
        self._waiters: list[tuple[Predicate, asyncio.Future[Record]]] = []
        self._listeners: list[Callable[[Record], None]] = []

    def __len__(self) -> int:
        return len(self._records)

    @overload
    def __getitem__(self, index: int) -> Record: ...

    @overload
    def __getitem__(self, index: slice) -> list[Record]: ...

    def __getitem__(self, index: int | slice) -> Record | list[Record]:
        if isinstance(index, slice):
            return list(self._records)[index]
        return self._records[index]

    def __iter__(self) -> Iterator[Record]:
        return iter(self._records)

    def add_listener(self, listener: Callable[[Record], None]) -> None:
        """Call ``listener`` with every record as it is appended (``frog-bt sim --log``)."""
        self._listeners.append(listener)

    def append(self, record: Record) -> None:
        self._records.append(record)
        for listener in self._listeners:
            listener(record)
        if self._waiters:
            keep = []
            for predicate, fut in self._waiters:
                if fut.done():
                    continue
                if predicate(record):
                    fut.set_result(record)
                else:
                    keep.append((predicate, fut))
            self._waiters = keep

    def received(self, channel: str | None = None, side: str | None = None) -> list[Record]:
        """What the simulator received (the executive sent), optionally on one channel/side."""
        return [
            r
            for r in self._records
            if r.direction == "in"
            and (channel is None or r.channel == channel)
            and (side is None or r.side == side)
        ]

    def sent(self, channel: str | None = None, side: str | None = None) -> list[Record]:
        """What the simulator sent, optionally on one channel/side."""
        return [
            r
            for r in self._records
            if r.direction == "out"
            and (channel is None or r.channel == channel)
            and (side is None or r.side == side)
        ]

    async def wait_for(self, predicate: Predicate, timeout: float) -> Record:
        """The first record (already logged, or still to come) satisfying ``predicate``.

        ``timeout`` is a wall-clock safety net: TimeoutError when it runs out.
        """
        for record in self._records:
            if predicate(record):
                return record
        fut: asyncio.Future[Record] = asyncio.get_running_loop().create_future()
        self._waiters.append((predicate, fut))
        try:
            return await asyncio.wait_for(fut, timeout)
        finally:
            if not fut.done():
                fut.cancel()
