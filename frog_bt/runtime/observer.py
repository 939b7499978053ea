"""Live observers of a running core: the MCAP recorder and its rotation, the tour summary,
the link states and the status line; rerun telemetry (:mod:`frog_bt.live.telemetry`) is one
too. Every one attaches the same way, :class:`Observer`: ``attach(host)`` appends its taps
to the host's (and keeps its work off the tick path), ``close()`` finishes it.

A :class:`Host` is what they attach to: the online executive, or a replay (which has no
raw wire traffic and no links: ``wire`` and ``links`` are None there).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from frog_bt.clock import Clock
    from frog_bt.config import Site
    from frog_bt.engine.core import Core, Taps
    from frog_bt.model.links import Links
    from frog_bt.runtime.executive import WireTaps


class Host(Protocol):
    """What an observer attaches to."""

    @property
    def site(self) -> Site: ...
    @property
    def clock(self) -> Clock: ...
    @property
    def sim_time(self) -> bool: ...
    @property
    def core(self) -> Core: ...
    @property
    def taps(self) -> Taps: ...
    @property
    def wire(self) -> WireTaps | None: ...  # raw traffic and link changes (live only)
    @property
    def links(self) -> Links | None: ...  # each link's state now (live only)


@runtime_checkable
class Observer(Protocol):
    def attach(self, host: Host) -> None:
        """Append this observer's taps to the host's; cheap, and never blocks a tick."""

    def close(self) -> None:
        """Finish (write what is left, close files); idempotent, bounded in time."""


def attach_all(host: Host, observers: Iterable[Observer]) -> list[Observer]:
    """Attach each observer in order; the list, for :func:`close_all`."""
    attached = []
    for observer in observers:
        observer.attach(host)
        attached.append(observer)
    return attached


def close_all(observers: Sequence[Observer]) -> None:
    """Close in the reverse order of attaching (the last attached may use the first)."""
    for observer in reversed(observers):
        observer.close()
