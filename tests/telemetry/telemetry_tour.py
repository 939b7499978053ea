"""One whole simulated tour with telemetry saved to an .rrd (the ``recorded`` fixture).

The tour runs like ``tests/e2e/tour.py`` (whose helpers it reuses): the real
executive against the built-in simulator in one event loop, on sim time, fast
(speed 400, short content). Telemetry is attached before the first tick.
"""

from __future__ import annotations

import asyncio
import sys
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "e2e"))
from tour import fast

from frog_bt.behaviours import load_tree
from frog_bt.config import Site, load_site
from frog_bt.live.telemetry import Telemetry
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.executive import Outcome
from frog_bt.runtime.observer import attach_all
from frog_bt.tree.loader import LoadedTree


@dataclass
class Recorded:
    """A finished tour and its recording, read back by entity path."""

    path: Path
    outcome: Outcome
    site: Site
    tree: LoadedTree
    telemetry: Telemetry
    ticks: int
    chunks: dict[str, list[Any]] = field(default_factory=dict)  # entity path -> chunks

    def rows(self, entity: str) -> int:
        """Temporal rows logged to ``entity``."""
        return sum(c.num_rows for c in self.chunks.get(entity, ()) if not c.is_static)

    def values(self, entity: str, component: str, *, static: bool = False) -> list[Any]:
        """Every value of ``component`` logged to ``entity`` (one list per row)."""
        out: list[Any] = []
        for chunk in self.chunks.get(entity, ()):
            if chunk.is_static != static:
                continue
            batch = chunk.to_record_batch()
            if component in batch.schema.names:
                out += batch.column(component).to_pylist()
        return out

    def texts(self, entity: str) -> list[str]:
        return [t for row in self.values(entity, "TextLog:text") for t in row]


async def _run_tour(path: Path) -> Recorded:
    import rerun as rr

    rr.set_strict_mode(True)  # a bad archetype raises (and counts in write_errors)
    site = load_site()
    tree = load_tree(site=site)
    telemetry = Telemetry.open(f"save:{path}", site, tree)
    rehearsal = Rehearsal(
        fast(),
        site=site,
        tree=tree,
        prepare=lambda executive: attach_all(executive, [telemetry]),
        memory=True,
    )
    try:
        async with rehearsal:
            outcome = await rehearsal.finish(60.0)
    finally:
        telemetry.close()
    executive = rehearsal.executive
    return Recorded(path, outcome, site, tree, telemetry, executive.core.ticks)


def record_tour(path: Path) -> Recorded:
    """Run the tour, then read the recording back (rerun.chunk.RrdReader)."""
    from rerun.chunk import RrdReader

    result = asyncio.run(_run_tour(path))
    chunks: dict[str, list[Any]] = defaultdict(list)
    for chunk in RrdReader(result.path).stream():
        chunks[chunk.entity_path].append(chunk)
    result.chunks = dict(chunks)
    return result
