"""One clock for every timer in frog-bt.

``Clock.now()`` is seconds since the Unix epoch (ROS time). Timers, timeouts,
resends and time of day all read it, so the same code runs on the wall clock on
the robot, on ``/clock`` with ``--sim-time``, and on a recording's timestamps in
replay or in tests.

* :class:`WallClock` — epoch-aligned but monotonic (immune to NTP steps).
* :class:`ManualClock` — moves only when told to (tests, replay).
* :class:`SimClock` — a :class:`ManualClock` fed by ``/clock``; ``wait_ready``
  blocks until the first ``/clock`` arrives, so nothing is timed before then.

Sleepers on a manual clock wake when the clock is advanced past their deadline,
in deadline order.
"""

from __future__ import annotations

import asyncio
import heapq
import itertools
import time
from abc import ABC, abstractmethod
from datetime import datetime
from zoneinfo import ZoneInfo

SITE_TZ = ZoneInfo("Europe/Madrid")


class Clock(ABC):
    """Source of time for every timer in the program."""

    tz = SITE_TZ

    @abstractmethod
    def now(self) -> float:
        """Seconds since the Unix epoch."""

    @abstractmethod
    async def sleep_until(self, deadline: float) -> None:
        """Return once ``now() >= deadline``."""

    async def sleep(self, seconds: float) -> None:
        await self.wait_ready()  # a duration counts from the first meaningful time
        await self.sleep_until(self.now() + max(0.0, seconds))

    async def wait_ready(self) -> None:  # noqa: B027 - wall clock is always ready
        """Return once the clock has a meaningful time."""

    @property
    def ready(self) -> bool:
        return True

    def local_time(self) -> datetime:
        """Time of day at the site (Europe/Madrid)."""
        return datetime.fromtimestamp(self.now(), self.tz)


class WallClock(Clock):
    """The real clock, epoch-aligned at start and monotonic afterwards."""

    def __init__(self) -> None:
        self._epoch0 = time.time()
        self._mono0 = time.monotonic()

    def now(self) -> float:
        return self._epoch0 + (time.monotonic() - self._mono0)

    async def sleep_until(self, deadline: float) -> None:
        delay = deadline - self.now()
        if delay > 0:
            await asyncio.sleep(delay)


class ManualClock(Clock):
    """A clock that moves only through :meth:`set` / :meth:`advance`.

    Time never goes backwards: an earlier time than the current one is ignored
    (a replayed or re-sent ``/clock`` must not rewind timers).
    """

    def __init__(self, start: float | None = None) -> None:
        self._now = 0.0 if start is None else float(start)
        self._ready = start is not None
        self._sleepers: list[tuple[float, int, asyncio.Future[None]]] = []
        self._order = itertools.count()
        self._ready_waiters: list[asyncio.Future[None]] = []

    def now(self) -> float:
        return self._now

    @property
    def ready(self) -> bool:
        return self._ready

    def set(self, t: float) -> None:
        if not self._ready:
            self._now = float(t)
            self._ready = True
            for fut in self._ready_waiters:
                if not fut.done():
                    fut.set_result(None)
            self._ready_waiters.clear()
        elif t > self._now:
            self._now = float(t)
        self._wake()

    def advance(self, seconds: float) -> None:
        self.set(self._now + seconds)

    def _wake(self) -> None:
        while self._sleepers and self._sleepers[0][0] <= self._now:
            _, _, fut = heapq.heappop(self._sleepers)
            if not fut.done():
                fut.set_result(None)

    @property
    def next_deadline(self) -> float | None:
        """Earliest pending sleeper deadline (replay jumps straight to it)."""
        while self._sleepers and self._sleepers[0][2].done():
            heapq.heappop(self._sleepers)
        return self._sleepers[0][0] if self._sleepers else None

    async def sleep_until(self, deadline: float) -> None:
        await self.wait_ready()
        if deadline <= self._now:
            return
        fut: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        heapq.heappush(self._sleepers, (deadline, next(self._order), fut))
        await fut

    async def wait_ready(self) -> None:
        if self._ready:
            return
        fut: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        self._ready_waiters.append(fut)
        await fut


class SimClock(ManualClock):
    """Simulated time from ``/clock`` (the ROS ``use_sim_time`` convention).

    Not ready until the first ``/clock`` message: :meth:`wait_ready` blocks
    until then and every timer waits with it.
    """

    def __init__(self) -> None:
        super().__init__(None)
