"""Reading a corpus through any :class:`concurrent.futures.Executor` (the seam batch
replay uses): one :func:`~frog_bt.offline.report.facts.read_file` per recording."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from pathlib import Path

from frog_bt.config import Site
from frog_bt.offline.report.facts import FileFacts, read_file


def read_corpus(
    files: list[Path],
    site: Site,
    executor: Executor,
    progress: Callable[[int, int], None] | None = None,
) -> list[FileFacts]:
    """Facts of every file, in the order given."""
    futures = [executor.submit(read_file, str(f), site) for f in files]
    out = []
    for done, future in enumerate(futures, 1):
        out.append(future.result())
        if progress is not None:
            progress(done, len(files))
    return out
