"""Work that yields to the robot: telemetry's writing runs when the event loop is quiet.

The recorder's writing (encoding, ``add_message``, ending a chunk) and telemetry's
pickling are not on the tick, but they share the executive's one thread with it. A
datagram that arrives while a chunk is being compressed waits for it (0.5-2 ms), and so
does the tick it calls for and the command that tick sends. :func:`soon` runs such work
as a *background job* instead: one job per turn of the event loop, and only when nothing
else is due — no callback ready (an input's, a tick's, a command being written) and no
socket with something to read. A job that finds the loop busy waits for the next turn.
For :data:`HOLD` after each tick (:func:`hold`, called by the executive) no job starts
either: the answers to the commands a tick sent (a front end's ack, a robot's reply)
often come within a millisecond, and go first; the job waits on a timer meanwhile, not
in a spin. After :data:`MAX_WAIT` a job no longer waits for a hold or a quiet turn; a
busy loop then still gets :data:`LATE_TURNS` more turns first, once every
:data:`MAX_WAIT`: an input that has just arrived is read, and the tick it calls for
runs, before the job (run at once, it made them wait: 0.3-0.8 ms in the reaction
bench's tail). The turns are taken behind what the next poll of the sockets finds (a
timer due now, not ``call_soon``: asyncio runs those first). Once per window, not per
job: a loop that is never quiet (the simulator beside the executive at 400x) drains a
backlog of jobs one a turn as before (waiting 50 ms a job instead, the tick bench
dropped half its batches; three turns a job, a few).

The test of "busy" reads two attributes of CPython's selector event loop (``_ready``,
the callbacks due now, and ``_selector``, polled without waiting); on a loop without
them every job runs at its turn, in order, as ``call_soon`` would. Without a running
loop (a replay, a test) :func:`soon` runs the job at once.
"""

from __future__ import annotations

import asyncio
import logging
import time
import weakref
from collections import deque
from collections.abc import Callable

log = logging.getLogger(__name__)

MAX_WAIT = 0.005  # seconds a job waits for a quiet turn (and a tick's hold) at most
LATE_TURNS = 2  # then: turns of a busy loop let go first (an input's read, its tick)
HOLD = 0.001  # seconds after a tick in which no job starts: the answers to its commands

Job = Callable[[], None]


class Background:
    """The background jobs of one event loop, run in the order they came (see the module
    docstring). Each job guards its own errors; one that raises is logged and the next
    runs."""

    def __init__(
        self,
        loop: asyncio.AbstractEventLoop,
        max_wait: float = MAX_WAIT,
        late_turns: int = LATE_TURNS,
    ) -> None:
        self.loop = loop
        self.max_wait = max_wait
        self.late_turns = late_turns
        self._turns_left = late_turns  # late turns left in this window
        self._refill_at = 0.0  # when the next window starts (monotonic)
        self._jobs: deque[tuple[float, Job]] = deque()
        self._turn: asyncio.Handle | asyncio.TimerHandle | None = None
        self.waited = 0  # turns a job let go by because the loop was busy
        self.forced = 0  # jobs run busy or not, late and after LATE_TURNS
        self._settled: list[asyncio.Future[None]] = []  # settled()'s waiters
        self._held_until = 0.0  # no job starts before this (monotonic), MAX_WAIT permitting

    def call(self, job: Job) -> None:
        """Run ``job`` at a quiet turn of the loop, after the jobs before it."""
        self._jobs.append((time.monotonic(), job))
        if self._turn is None:
            self._turn = self.loop.call_soon(self._run)

    def hold(self, seconds: float = HOLD) -> None:
        """Start no job for ``seconds`` (the executive, after a tick: what it sent is
        often answered within a millisecond, and the answer goes first)."""
        self._held_until = max(self._held_until, time.monotonic() + seconds)

    def busy(self) -> bool:
        """Is something more urgent due: a callback ready, or a socket with input?"""
        if getattr(self.loop, "_ready", None):
            return True
        selector = getattr(self.loop, "_selector", None)
        return selector is not None and bool(selector.select(0))

    def _run(self) -> None:
        self._turn = None
        if not self._jobs:
            return
        since, job = self._jobs[0]
        now = time.monotonic()
        if now - since < self.max_wait and now < self._held_until:
            self.waited += 1  # a timer, not a spin: the loop may sleep
            wait = min(self._held_until, since + self.max_wait) - now
            self._turn = self.loop.call_later(wait, self._run)
            return
        if self.busy():
            if now - since < self.max_wait:
                self.waited += 1
                self._turn = self.loop.call_soon(self._run)
                return
            if self._turns_left > 0:  # late: a turn behind what the next poll finds
                self._turns_left -= 1
                self.waited += 1
                self._turn = self.loop.call_later(0, self._run)
                return
            self.forced += 1
        if now >= self._refill_at:
            self._turns_left, self._refill_at = self.late_turns, now + self.max_wait
        self._jobs.popleft()
        try:
            job()
        except Exception:
            log.exception("background job %r failed", job)
        if self._jobs:
            if self._turn is None:
                self._turn = self.loop.call_soon(self._run)
        else:
            self._wake_settled()

    async def settled(self) -> None:
        """Return once no job is waiting (a test's, a writer's closing wait)."""
        while self._jobs:
            waiter = self.loop.create_future()
            self._settled.append(waiter)
            await waiter

    def _wake_settled(self) -> None:
        waiters, self._settled = self._settled, []
        for waiter in waiters:
            if not waiter.done():
                waiter.set_result(None)


_LOOPS: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, Background] = (
    weakref.WeakKeyDictionary()
)


def of(loop: asyncio.AbstractEventLoop) -> Background:
    """The background jobs of ``loop`` (made on first use; they go with the loop)."""
    jobs = _LOOPS.get(loop)
    if jobs is None:
        jobs = _LOOPS[loop] = Background(loop)
    return jobs


async def settled() -> None:
    """Return once the running loop's background jobs are all done."""
    await of(asyncio.get_running_loop()).settled()


def hold(seconds: float = HOLD) -> None:
    """Start no job of the running loop for ``seconds`` (:meth:`Background.hold`);
    nothing without a running loop."""
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        return
    of(loop).hold(seconds)


def soon(job: Job) -> None:
    """Run ``job`` at a quiet turn of the running loop; at once without one."""
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        job()
        return
    of(loop).call(job)
