"""What the two telemetry writers share: an :class:`~frog_bt.runtime.observer.Observer` whose
taps fill :class:`~frog_bt.live.telemetry.rows.Rows` on the tick path and whose rows leave after
the tick. :class:`~frog_bt.live.telemetry.Telemetry` writes them to rerun in this process;
:class:`~frog_bt.live.telemetry.process.TelemetryProcess` hands them to a child that does.
"""

from __future__ import annotations

import asyncio
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

from frog_bt.live.telemetry.layout import TreeIndex
from frog_bt.live.telemetry.rows import Rows
from frog_bt.model.events import Event, LinksChanged, Ticked
from frog_bt.model.links import LinkStatus, changed

if TYPE_CHECKING:
    from frog_bt.config import Site
    from frog_bt.engine.core import Core
    from frog_bt.model.links import Links
    from frog_bt.runtime.observer import Host
    from frog_bt.tree.loader import LoadedTree


class TelemetryObserver(ABC):
    """Rows of one core, and the links' changes; see the subclasses for where they go."""

    def __init__(self, site: Site, tree: LoadedTree, *, batch_ticks: int) -> None:
        self.site = site
        self.tree = tree
        self.index = TreeIndex.of(tree.root)
        self.generation = 1  # the tree's number: a reload (run --watch) starts the next
        self.rows = Rows(site, self.index, batch_ticks=batch_ticks, on_full=self._full)
        self._host: Host | None = None
        self._links: dict[str, LinkStatus] = {}
        self._closed = False
        self._flush_pending = False

    def attach(self, host: Host) -> None:
        """Follow the host's events and, live, each link's state."""
        self.rows.attach(host)
        self._host = host
        self._core = host.core
        links = host.links
        if links is not None:
            self.on_links(host.clock.now() if host.clock.ready else 0.0, links)

    def on_event(self, event: Event) -> None:
        if isinstance(event, LinksChanged):
            self.on_links(event.t, event.links)
            return
        if type(event) is Ticked and self._host is not None and self._host.core is not self._core:
            self._reloaded(self._host.core, event.t)
        self.rows.on_event(event)

    def _reloaded(self, core: Core, t: float) -> None:
        """The host runs another tree (``run --watch``): what was buffered goes out with the
        old tree's numbering, then the new tree is numbered, sent and followed."""
        self.flush()
        self._core = core
        self.tree = core.tree
        self.index = TreeIndex.of(core.tree.root)
        self.generation += 1
        self.rows.reindex(self.index)
        self._write_tree(core.ticks, t, TreeIndex(self.index.nodes), self.generation)

    def on_links(self, t: float, links: Links) -> None:
        changes = changed(self._links, links)
        if changes and not self._closed:
            core = self._host.core if self._host is not None else None
            self._write_links(core.ticks if core is not None else 0, t, changes)

    def _full(self) -> None:
        """Rows are full (called inside a tick): write them once the tick is over, so that
        what the tick sent leaves first and the tick itself stays short; at once when no
        event loop runs (replay)."""
        if self._flush_pending:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            self.flush()
            return
        self._flush_pending = True
        loop.call_soon(self._flush_soon)

    @abstractmethod
    def _write_tree(self, tick: int, t: float, index: TreeIndex, generation: int) -> None:
        """A reloaded tree (its nodes only), from ``tick`` on."""

    @abstractmethod
    def _write_links(self, tick: int, t: float, changes: list[tuple[str, LinkStatus]]) -> None: ...

    @abstractmethod
    def _flush_soon(self) -> None:
        """After the tick that filled the rows (clears ``_flush_pending``)."""

    @abstractmethod
    def flush(self) -> None:
        """Write (or hand over) the buffered rows now."""

    @abstractmethod
    def close(self) -> None:
        """Write what is left and finish; idempotent, bounded in time."""
