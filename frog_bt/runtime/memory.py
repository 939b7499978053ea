"""Flat memory for a process that runs all day: glibc's malloc thresholds pinned.

glibc raises its mmap threshold each time a large block (the recorder's 256 KiB
chunks, rerun's and numpy's buffers) is freed, so later blocks of that size come
from the heap instead, where the small objects allocated around them keep the
heap from shrinking: RSS crept up by 30 to 70 KB per tour (docs/PERFORMANCE.md).
Setting ``M_MMAP_THRESHOLD`` and ``M_TRIM_THRESHOLD`` explicitly (to glibc's own
starting values) turns that adjustment off: large blocks are mapped and
unmapped, the heap's free top is given back, RSS stays flat.
``MALLOC_MMAP_THRESHOLD_`` in the environment does the same, and wins.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters
MMAP_THRESHOLD = 128 * 1024  # bytes: glibc's default starting values
TRIM_THRESHOLD = 128 * 1024


def pin_malloc_thresholds() -> bool:
    """Pin the mmap threshold where glibc is the allocator; True when it was set."""
    if "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return False
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
