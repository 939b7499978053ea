"""Memory for a process that runs all day: glibc's malloc thresholds pinned, the
start-up's objects frozen out of the cyclic collector's way (below).

glibc raises its mmap threshold each time a large block (asyncio's 256 KiB read
buffers, the recorder's chunks) is freed, so later blocks of that size come
from the heap instead, where the small objects allocated around them keep the
heap from shrinking: RSS crept up by 30 to 70 KB per tour (docs/PERFORMANCE.md).
Setting ``M_MMAP_THRESHOLD`` and ``M_TRIM_THRESHOLD`` explicitly turns that
adjustment off: blocks from 1 MiB are mapped and unmapped, the heap's free top beyond
2 MiB is given back, RSS stays flat. Not glibc's starting values (128 KiB each): asyncio
reads each socket into a 256 KiB buffer, which at 128 KiB was mapped, faulted in and
unmapped on every read, and the heap's top trimmed and grown again all the time (the
tick 4-5 % slower, telemetry or not: docs/PERFORMANCE.md, "sixth pass").
``MALLOC_MMAP_THRESHOLD_`` in the environment wins over both.
"""

from __future__ import annotations

import asyncio
import gc
import os
from typing import TYPE_CHECKING

from frog_bt.model.events import Event, Ticked
from frog_bt.runtime import background

if TYPE_CHECKING:
    from frog_bt.engine.core import Core
    from frog_bt.runtime.observer import Host

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters
MMAP_THRESHOLD = 1024 * 1024  # bytes: above asyncio's 256 KiB read buffer, with room
TRIM_THRESHOLD = 2 * 1024 * 1024  # the heap's free top kept before it is given back


def pin_malloc_thresholds() -> bool:
    """Pin the mmap threshold where glibc is the allocator; True when it was set."""
    if "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return False
    import ctypes  # here, not with the module: `run` imports it before loading (below)
    import ctypes.util

    name = ctypes.util.find_library("c")
    if not name:
        return False
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (musl, macOS): nothing to pin
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(
        mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD) and mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD)
    )


# ---------------------------------------------------------------- the cyclic collector
#
# Start-up allocates tens of thousands of objects (modules, classes, the site, the tree:
# about 46,000 alive once loaded) and frees almost none: the collector's runs then only
# cost time (a full one 20-60 ms). And they stay in the oldest generation for the whole
# day, so that every later full collection walks all of them again, from inside
# whichever callback it falls in (one of 64 ms seen with telemetry on; 26-28 ms at the
# end of a 30-stop tour, 7.5 ms frozen: docs/PERFORMANCE.md). So the ``run`` command
# starts with the collector off, and once the site and the tree are loaded moves
# everything alive into the permanent generation (gc.freeze): full collections then
# walk only what the day allocated. Frozen objects are never collected as cycles
# (reference counting still frees the others): what is garbage in cycles at that moment
# stays (about 1,300 objects at a start, some 100 KB, once), which is why a reload
# thaws, collects and freezes again (:class:`HeapKeeper`): the old tree must go.


def hold_collector() -> None:
    """No cyclic collections until :func:`freeze_heap` (start-up: nothing to free)."""
    gc.disable()


def freeze_heap() -> None:
    """What is alive now is kept for good (the collector no longer walks it), and the
    collector is on again. (Not ``gc.get_freeze_count()``: it walks what is frozen.)"""
    gc.freeze()
    gc.enable()


def refreeze_heap() -> int:
    """After a reload: thaw, collect what the old tree left (a full collection, at an
    idle point), freeze what is alive; the number of objects collected."""
    gc.unfreeze()
    found = gc.collect()
    gc.freeze()
    return found


class HeapKeeper:
    """An observer of the ``run`` command: when the host runs another tree (``run
    --watch`` swapped it in at an idle point, docked), :func:`refreeze_heap` once that
    tick is over, so that the old tree is collected and the new one frozen."""

    def __init__(self) -> None:
        self._host: Host | None = None
        self._core: Core | None = None
        self.refrozen = 0  # reloads followed

    def attach(self, host: Host) -> None:
        self._host = host
        self._core = host.core

    def on_event(self, event: Event) -> None:
        host = self._host
        if host is None or type(event) is not Ticked or host.core is self._core:
            return
        self._core = host.core
        try:
            asyncio.get_running_loop().call_soon(self._refreeze)
        except RuntimeError:
            self._refreeze()

    def _refreeze(self) -> None:
        refreeze_heap()
        self.refrozen += 1

    def close(self) -> None:
        self._host = self._core = None


# A young collection takes 0.2-0.4 ms and an intermediate one 0.7-1.2 ms; left to
# itself the collector runs one wherever the 700th allocation falls: 13 a second in the
# reaction bench, some inside the tick an input called for (docs/PERFORMANCE.md).
QUIET_AFTER = 700  # allocations (CPython's own gen-0 threshold): a collection is due
BACKSTOP = 20_000  # the collector's own gen-0 threshold meanwhile: it runs by itself past it
OLDER_EVERY = 10  # collections of one generation before the next one is collected too


class QuietCollector:
    """An observer of the ``run`` command: the cyclic collector runs at quiet turns of
    the event loop (a :mod:`~frog_bt.runtime.background` job: an input that is waiting
    and its tick go first), not inside whichever callback allocates the 700th object.

    Once a tick ends with a collection due (:data:`QUIET_AFTER` allocations), one job
    collects the youngest generation, or an older one as CPython would (every
    :data:`OLDER_EVERY` of the younger). Meanwhile the collector's own threshold is
    :data:`BACKSTOP`, so that it still runs by itself if no tick comes (loading, a
    stalled loop); :meth:`close` puts the thresholds back."""

    def __init__(self) -> None:
        self._due = False
        self._thresholds: tuple[int, int, int] | None = None
        self.collected = [0, 0, 0]  # collections run, by generation (tests, bench)

    def attach(self, host: Host) -> None:
        if self._thresholds is None:
            self._thresholds = gc.get_threshold()
            gc.set_threshold(BACKSTOP, OLDER_EVERY, OLDER_EVERY)

    def on_event(self, event: Event) -> None:
        if type(event) is Ticked and not self._due and gc.get_count()[0] >= QUIET_AFTER:
            self._due = True
            background.soon(self._collect)

    def _collect(self) -> None:
        self._due = False
        if not gc.isenabled():  # held (start-up, a reload's refreeze): not now
            return
        _, young, middle = gc.get_count()
        generation = 2 if middle >= OLDER_EVERY else 1 if young >= OLDER_EVERY else 0
        gc.collect(generation)
        self.collected[generation] += 1

    def close(self) -> None:
        if self._thresholds is not None:
            gc.set_threshold(*self._thresholds)
            self._thresholds = None
