"""How the telemetry child is scheduled: on an otherwise free CPU, and never left behind.

Traced on a two-vCPU machine (docs/PERFORMANCE.md, "fifth pass"): the child at niceness
5 kept a CPU for up to 3.5 ms at a time (rerun's ``file_writer`` thread for 2.5 ms) while
the robot's side of a reaction waited to run. Under ``SCHED_IDLE`` a waking task of any
other class takes the CPU from it at once, and the kernel counts a CPU that runs only
idle-class tasks as free when it places a waking one.

An idle-class task may get almost nothing on a machine busy all the time, so the
executive (at normal priority) watches the child's backlog: from :data:`BEHIND`
batches waiting it puts the child back at niceness 5 (:meth:`ChildPriority.follow`),
and back in the idle class only once none has waited for :data:`CALM` seconds. (Lowered
as soon as the queue was short, the child was starved again in the middle of writing
what it had just read: the tick bench at 400x dropped half its batches.) Closing raises it too (both
sides: the child itself when it reads ``close``), so that it finishes its file within
its time.

Going back from ``SCHED_IDLE`` needs ``CAP_SYS_NICE`` or an ``RLIMIT_NICE`` that
allows the child's niceness (root usually has the first; a container may not). Where
:func:`can_raise` finds neither, the child is only niced, as before.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
from collections.abc import Callable
from pathlib import Path

log = logging.getLogger(__name__)

NICE = 5  # the child's niceness when it is not in the idle class
BEHIND = 8  # batches waiting for the child (of QUEUE_BATCHES) that raise it
CAUGHT_UP = 1  # at most this many waiting: caught up
CALM = 60.0  # seconds caught up before a raised child goes back to the idle class

_IDLE = getattr(os, "SCHED_IDLE", None)
_OTHER = getattr(os, "SCHED_OTHER", None)


def can_raise() -> bool:
    """Whether this process may take a niced thread out of ``SCHED_IDLE`` again.

    Tried on a thread of its own, which ends after the try: whatever the answer, no
    thread that goes on running is left in the idle class."""
    if _IDLE is None or _OTHER is None:
        return False
    answer: list[bool] = []

    def probe() -> None:
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), NICE)
            os.sched_setscheduler(0, _IDLE, os.sched_param(0))
            os.sched_setscheduler(0, _OTHER, os.sched_param(0))
        except OSError:
            answer.append(False)
        else:
            answer.append(True)

    thread = threading.Thread(target=probe, name="frog-bt sched probe", daemon=True)
    thread.start()
    thread.join()
    return answer == [True]


def enter(idle: bool) -> None:
    """The child's first step, before its threads start (they inherit it): niceness
    :data:`NICE`, and the idle class when ``idle``."""
    with contextlib.suppress(OSError):
        os.nice(NICE)
    if idle and _IDLE is not None:
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, _IDLE, os.sched_param(0))


def leave() -> None:
    """The child, closing: every thread of it back at niceness :data:`NICE` (where
    :func:`can_raise` said it may), to finish its file within its time."""
    ChildPriority(os.getpid(), idle=True).finish()


class ChildPriority:
    """The executive's side: moves every thread of the child ``pid`` between the idle
    class and niceness :data:`NICE`, by how many batches wait for it."""

    def __init__(
        self, pid: int, *, idle: bool, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.pid = pid
        self.enabled = idle  # the child started idle, and can be raised
        self.idle = idle
        self.raised = 0  # times it was raised (it fell behind), for the log and tests
        self._clock = clock
        self._busy_at = 0.0  # when more than CAUGHT_UP last waited (clock's time)
        self._finishing = False  # finish() was called: raised for good

    def follow(self, backlog: Callable[[], int]) -> None:
        """After a hand-over: raise the child from :data:`BEHIND` batches waiting
        (``backlog()``: asked only when enabled, as a queue's ``qsize`` is not
        everywhere); lower it again once no more than :data:`CAUGHT_UP` have waited for
        :data:`CALM`."""
        if not self.enabled or self._finishing:
            return
        waiting = backlog()
        now = self._clock()
        if waiting > CAUGHT_UP:
            self._busy_at = now
        if self.idle and waiting >= BEHIND:
            self.raised += 1
            log.info("rerun telemetry: the writer is %d batches behind; raised", waiting)
            self._set(idle=False)
        elif not self.idle and now - self._busy_at >= CALM:
            self._set(idle=True)

    def finish(self) -> None:
        """Before closing: at niceness :data:`NICE` for good (the hand-overs of what is
        left no longer lower it), so that it finishes within its time."""
        self._finishing = True
        if self.enabled and self.idle:
            self._set(idle=False)

    def _set(self, *, idle: bool) -> None:
        self.idle = idle
        policy = _IDLE if idle else _OTHER
        assert policy is not None
        try:
            tids = [int(t.name) for t in Path(f"/proc/{self.pid}/task").iterdir()]
        except OSError:  # the child is gone
            return
        for tid in tids:
            with contextlib.suppress(OSError):  # a thread that ended meanwhile
                os.sched_setscheduler(tid, policy, os.sched_param(0))
