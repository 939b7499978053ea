"""mcap's writer, faster where it holds the event loop.

Two things mcap's ``Writer`` does when the recorder ends a chunk cost more than they
need to, and :func:`install` replaces them (``tests/recording/test_mcap_speed.py``
checks that the bytes are the same):

* **The chunk's message index.** ``MessageIndex.write`` writes one ``(log_time,
  offset)`` entry per message with two ``struct.pack`` calls and two buffer writes
  each (~0.6 µs a message); here all the entries are packed with one ``struct.pack``.
* **The zstd compressor.** mcap calls ``zstandard.compress`` for each chunk, which
  makes a compression context (a few MB) each time. With glibc's mmap threshold
  pinned (:mod:`frog_bt.runtime.memory`), those are fresh pages every time: ~0.23 ms
  a 64 KiB chunk instead of ~0.05 ms. Here one ``ZstdCompressor`` (at
  :data:`ZSTD_LEVEL`) is made once and reused (the recorder writes from the event
  loop's thread only; a forked child gets its own copy). Its frames are the ones
  ``zstandard.compress`` makes at that level.

mcap has no hooks for either; the method and the module mcap's writer calls are
replaced once, when the recorder is imported. A later mcap that changes the index
record's layout or its compression call fails that test rather than writing a
different file.
"""

from __future__ import annotations

import struct
from itertools import chain
from types import SimpleNamespace
from typing import Any

import mcap.writer
import zstandard
from mcap import records
from mcap.opcode import Opcode

_ORIGINAL = records.MessageIndex.write
# zstd's level 1, not mcap's 3: ~40 % less time a chunk with cold caches (as the
# recorder's are, between chunks), files ~3 % larger (docs/PERFORMANCE.md)
ZSTD_LEVEL = 1


def _write(self: records.MessageIndex, stream: Any) -> None:
    """``MessageIndex.write``: opcode, channel id, the entries' length, the entries."""
    entries = self.records
    stream.start_record(Opcode.MESSAGE_INDEX)
    stream.write(
        struct.pack(
            f"<HI{2 * len(entries)}Q",
            self.channel_id,
            16 * len(entries),
            *chain.from_iterable(entries),
        )
    )
    stream.finish_record()


def install() -> None:
    """Make mcap's writer use :func:`_write` and one reused compressor (idempotent)."""
    records.MessageIndex.write = _write  # type: ignore[method-assign]
    if not isinstance(getattr(mcap.writer, "zstandard", None), SimpleNamespace):
        compressor = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
        setattr(mcap.writer, "zstandard", SimpleNamespace(compress=compressor.compress))  # noqa: B010


def original() -> Any:
    """mcap's own ``MessageIndex.write`` (for the test that compares the two)."""
    return _ORIGINAL
