"""The telemetry child's scheduling: idle class while it keeps up, niced when behind."""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from frog_bt.live.telemetry import priority
from frog_bt.live.telemetry.priority import BEHIND, CALM, CAUGHT_UP, NICE, ChildPriority

pytestmark = pytest.mark.skipif(not hasattr(os, "SCHED_IDLE"), reason="Linux scheduling")


def _child(
    idle: bool, ready: multiprocessing.synchronize.Event, stop: multiprocessing.synchronize.Event
) -> None:
    priority.enter(idle)
    threads = [threading.Thread(target=stop.wait) for _ in range(2)]  # as rerun's
    for thread in threads:
        thread.start()
    ready.set()
    stop.wait(30)


@pytest.fixture
def child() -> Iterator[int]:
    """A forked child in the idle class with two threads of its own; its pid."""
    context = multiprocessing.get_context("fork")
    ready, stop = context.Event(), context.Event()
    process = context.Process(target=_child, args=(True, ready, stop), daemon=True)
    process.start()
    assert ready.wait(10)
    assert process.pid is not None
    yield process.pid
    stop.set()
    process.join(10)


def _by_thread(pid: int) -> dict[int, tuple[int, int]]:
    """(policy, niceness) of each thread of ``pid``, by thread id."""
    found = {}
    for task in Path(f"/proc/{pid}/task").iterdir():
        tid = int(task.name)
        with contextlib.suppress(OSError):  # ended meanwhile
            found[tid] = (os.sched_getscheduler(tid), os.getpriority(os.PRIO_PROCESS, tid))
    return found


def _threads(pid: int) -> list[tuple[int, int]]:
    """(policy, niceness) of each thread of ``pid``."""
    return list(_by_thread(pid).values())


IDLE = (os.SCHED_IDLE, NICE) if hasattr(os, "SCHED_IDLE") else ()
NICED = (os.SCHED_OTHER, NICE) if hasattr(os, "SCHED_OTHER") else ()


def test_the_probe_leaves_no_running_thread_idle() -> None:
    before = _by_thread(os.getpid())
    priority.can_raise()
    after = _by_thread(os.getpid())  # other threads (a test runner's) may come and go
    assert all(after[tid] == before[tid] for tid in before.keys() & after.keys())
    assert all(policy != os.SCHED_IDLE for policy, _ in after.values())


needs_raise = pytest.mark.skipif(not priority.can_raise(), reason="no CAP_SYS_NICE here")


@needs_raise
def test_the_child_and_its_threads_start_idle_and_niced(child: int) -> None:
    assert set(_threads(child)) == {IDLE}
    assert len(_threads(child)) == 3


@needs_raise
def test_a_child_behind_is_raised_and_lowered_after_a_calm_minute(child: int) -> None:
    now = [0.0]
    prio = ChildPriority(child, idle=True, clock=lambda: now[0])
    prio.follow(lambda: BEHIND - 1)
    assert set(_threads(child)) == {IDLE}  # a few batches waiting: left as it is
    prio.follow(lambda: BEHIND)
    assert set(_threads(child)) == {NICED} and prio.raised == 1
    now[0] = CALM / 2
    prio.follow(lambda: CAUGHT_UP)
    assert set(_threads(child)) == {NICED}  # caught up, not for long: still writing
    now[0] = CALM
    prio.follow(lambda: CAUGHT_UP + 1)
    assert set(_threads(child)) == {NICED}  # behind again: the calm starts over
    now[0] = 2 * CALM - 1
    prio.follow(lambda: CAUGHT_UP)
    assert set(_threads(child)) == {NICED}
    now[0] = 2 * CALM
    prio.follow(lambda: CAUGHT_UP)
    assert set(_threads(child)) == {IDLE}  # a calm minute: back in the idle class
    prio.finish()  # closing: finishes its file at niceness 5
    assert set(_threads(child)) == {NICED}
    now[0] = 10 * CALM
    prio.follow(lambda: 0)  # what is left, handed over while closing: stays raised
    assert set(_threads(child)) == {NICED}


def test_where_it_could_not_be_raised_the_child_is_only_niced(child: int) -> None:
    def unasked() -> int:  # a queue's qsize where it is missing (macOS)
        raise NotImplementedError

    prio = ChildPriority(child, idle=False)  # can_raise() said no: the child started niced
    prio.follow(unasked)
    prio.follow(lambda: 0)
    prio.finish()
    assert set(_threads(child)) == {IDLE}  # untouched (this child was started idle)
    assert prio.raised == 0


def test_a_child_that_is_gone_is_left_alone() -> None:
    prio = ChildPriority(2**22 + 1, idle=True)  # above pid_max's default: no such process
    prio.follow(lambda: BEHIND)
    prio.finish()
    assert prio.raised == 1


def test_the_executive_says_idle_only_where_it_could_raise_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def refuse(pid: int, policy: int, param: object) -> None:
        if policy != os.SCHED_IDLE:
            raise PermissionError("no CAP_SYS_NICE")

    monkeypatch.setattr(os, "sched_setscheduler", refuse)
    assert priority.can_raise() is False


@needs_raise
def test_the_telemetry_child_runs_idle_and_finishes_its_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.live.telemetry import process

    entered = multiprocessing.get_context("fork").Event()
    enter = process.enter

    def entering(idle: bool) -> None:  # the forked child's first step, then a signal
        enter(idle)
        entered.set()

    monkeypatch.setattr(process, "enter", entering)
    site = load_site()
    telemetry = process.TelemetryProcess(f"save:{tmp_path / 't.rrd'}", site, load_tree(site=site))
    child = telemetry._child
    assert child.pid is not None and entered.wait(10)
    assert os.sched_getscheduler(child.pid) == os.SCHED_IDLE
    assert telemetry.priority.enabled and telemetry.priority.idle
    assert telemetry.priority.pid == child.pid
    telemetry.close()
    assert child.exitcode == 0 and (tmp_path / "t.rrd").stat().st_size > 0
