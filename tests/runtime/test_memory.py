"""The cyclic collector around start-up and reloads (frog_bt.runtime.memory)."""

from __future__ import annotations

import asyncio
import gc
import weakref
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pytest

from frog_bt.cli import main
from frog_bt.model.events import Ticked
from frog_bt.runtime import background, memory


class _Node:
    """An object in a cycle with itself: only the cyclic collector frees it."""

    def __init__(self) -> None:
        self.me = self


@pytest.fixture
def thawed() -> Iterator[None]:
    """Whatever a test freezes is thawed again, and the collector left on."""
    yield
    gc.unfreeze()
    gc.enable()


def test_start_up_objects_are_frozen_and_a_reload_frees_the_old_ones(thawed: None) -> None:
    """What is alive at the freeze is out of the collector's way (a full collection does
    not walk or free it, even once it is garbage); refreezing, as after a reload, frees
    it."""
    old = _Node()
    gone = weakref.ref(old)
    memory.hold_collector()
    assert not gc.isenabled()
    memory.freeze_heap()
    assert gc.isenabled() and gc.get_freeze_count() > 0
    del old
    gc.collect()
    assert gone() is not None  # frozen: kept, though garbage
    assert memory.refreeze_heap() >= 1
    assert gone() is None and gc.get_freeze_count() > 0


def test_the_heap_keeper_refreezes_when_the_host_runs_another_tree(thawed: None) -> None:
    core = _Node()
    gone = weakref.ref(core)
    host = SimpleNamespace(core=core)
    keeper = memory.HeapKeeper()
    keeper.attach(host)  # type: ignore[arg-type]
    memory.freeze_heap()
    ticked = Ticked(1.0, 1, "RUNNING")
    keeper.on_event(ticked)
    assert keeper.refrozen == 0  # the same tree: nothing to do
    host.core = _Node()  # a reload swapped the tree in
    del core
    keeper.on_event(ticked)  # no event loop here: at once
    assert keeper.refrozen == 1 and gone() is None


def test_a_run_that_cannot_start_leaves_the_collector_on(tmp_path: Path) -> None:
    assert main(["run", "--config", str(tmp_path / "missing.yaml")]) == 2
    assert gc.isenabled()


def test_the_collector_runs_at_a_quiet_turn_after_the_tick_that_made_it_due() -> None:
    """Left to itself the collector would run inside the 700th allocation's callback;
    here a tick that ends with a collection due queues it as a background job (after
    what is waiting), the backstop threshold keeps it from running by itself meanwhile,
    and every tenth collection takes the next generation too."""
    before = gc.get_threshold()
    collector = memory.QuietCollector()
    collector.attach(SimpleNamespace())  # type: ignore[arg-type]
    ticked = Ticked(1.0, 1, "RUNNING")

    async def scenario() -> tuple[list[str], bool]:
        order: list[str] = []
        gc.collect()
        garbage = [_Node() for _ in range(memory.QUIET_AFTER // 4)]
        gone = weakref.ref(garbage[0])  # each in a cycle: only the collector frees it
        del garbage
        collector.on_event(Ticked(1.0, 1, "RUNNING"))  # not due: fewer allocations
        assert collector.collected == [0, 0, 0]
        more = [_Node() for _ in range(memory.QUIET_AFTER)]
        del more
        asyncio.get_running_loop().call_soon(lambda: order.append("input"))
        collector.on_event(ticked)  # due now: queued, not run
        assert gone() is not None and collector.collected == [0, 0, 0]
        await background.settled()
        order.append(f"collected {collector.collected}")
        return order, gone() is None

    try:
        assert gc.get_threshold()[0] == memory.BACKSTOP
        order, freed = asyncio.run(scenario())
        assert order == ["input", "collected [1, 0, 0]"] and freed
        for _ in range(memory.OLDER_EVERY):
            gc.collect(0)  # as ten collections of the youngest would
        collector._due = True
        collector._collect()
        assert collector.collected == [1, 1, 0]
    finally:
        collector.close()
    assert gc.get_threshold() == before


def test_malloc_thresholds_leave_asyncios_read_buffer_on_the_heap() -> None:
    # asyncio reads every socket into a buffer of max_size bytes: at or above the pinned
    # mmap threshold, each read was mapped, faulted in and unmapped (the tick 4-5 % slower)
    from asyncio.selector_events import _SelectorSocketTransport

    assert 2 * _SelectorSocketTransport.max_size < memory.MMAP_THRESHOLD
    assert memory.TRIM_THRESHOLD >= memory.MMAP_THRESHOLD
