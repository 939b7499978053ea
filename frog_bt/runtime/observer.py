"""How observers hear the executive: one typed event stream.

Every observer — the MCAP recorder and its rotation, the tour summary, the status line,
the console's day, rerun telemetry, webhooks — attaches the same way: the host calls
:meth:`Observer.attach` once (the observer keeps the host: its site, clock and *current*
core, which a reload replaces), then :meth:`Observer.on_event` with each
:data:`~frog_bt.model.events.Event`, in order, and :meth:`Observer.close` at the end.
``on_event`` runs on the tick path: it must be quick and never block.

A :class:`Host` is the online executive, or a replay (which has no links: ``links`` is
None there). :class:`Observers` is the list a host keeps and tells.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from frog_bt.model.events import Event
from frog_bt.text import LINE, escape

log = logging.getLogger(__name__)

if TYPE_CHECKING:
    from frog_bt.clock import Clock
    from frog_bt.config import Site
    from frog_bt.engine.core import Core
    from frog_bt.model.links import Links

__all__ = ["Host", "Listener", "Observer", "Observers", "attach_all", "close_all", "listen"]


class Host(Protocol):
    """What an observer attaches to."""

    @property
    def site(self) -> Site: ...
    @property
    def clock(self) -> Clock: ...
    @property
    def sim_time(self) -> bool: ...
    @property
    def core(self) -> Core: ...  # the core running now (a reload replaces it)
    @property
    def links(self) -> Links | None: ...  # each link's state now (live only)
    @property
    def observers(self) -> Observers: ...


@runtime_checkable
class Observer(Protocol):
    def attach(self, host: Host) -> None:
        """Keep the host and start (open files, write what is static); cheap."""

    def on_event(self, event: Event) -> None:
        """One event of the executive; on the tick path: quick, never blocking."""

    def close(self) -> None:
        """Finish (write what is left, close files); idempotent, bounded in time."""


class Observers:
    """The observers of one host, told every event in the order they attached."""

    def __init__(self) -> None:
        self._observers: list[Observer] = []
        self._calls: list[Callable[[Event], None]] = []  # their on_event, bound once
        self._later: list[Event] = []  # told once the current callback is over (later())
        self._scheduled = False
        # The host settles itself once its callback (the tick) is over: later() then only
        # holds the event (no loop handle per tick). The executive does, after the tick's
        # commands have gone out.
        self.host_settles = False
        self.failures: dict[tuple[str, str], int] = {}  # (observer, error) -> how many

    def __bool__(self) -> bool:
        return bool(self._observers)

    def attach(self, host: Host, observers: Iterable[Observer]) -> list[Observer]:
        """Attach each observer to ``host`` in order; the list of those attached."""
        attached = []
        for observer in observers:
            observer.attach(host)
            self._observers.append(observer)
            self._calls.append(observer.on_event)
            attached.append(observer)
        return attached

    def detach(self, observer: Observer) -> None:
        """Stop telling ``observer`` (it is not closed)."""
        if observer in self._observers:
            i = self._observers.index(observer)
            del self._observers[i], self._calls[i]

    def emit(self, event: Event) -> None:
        """Tell every observer, in the order they attached. An observer that fails is
        counted and logged once (per observer and kind of error), never the tick's end."""
        if self._later:
            self.settle()
        for call in self._calls:
            try:
                call(event)
            except Exception as exc:
                self.failed(call, exc, event)

    def failed(self, call: Callable[[Event], None], exc: Exception, event: Event) -> None:
        owner = type(getattr(call, "__self__", call)).__name__
        key = (owner, type(exc).__name__)
        self.failures[key] = self.failures.get(key, 0) + 1
        if self.failures[key] == 1:
            log.error(
                "observer %s failed on %s: %s; going on (further ones are counted)",
                owner,
                type(event).__name__,
                escape(f"{type(exc).__name__}: {exc}")[:LINE],
            )

    def later(self, event: Event) -> None:
        """Tell ``event`` once the event loop's current callback (the tick) is over, still
        before any later event and before the next tick (:meth:`settle`, which the core
        calls as a tick starts): the order every observer hears is the same, and their
        work on a tick's end (telemetry's statuses, the recorder's tick record, the status
        line) is off the tick's path. At once without an event loop (replay)."""
        self._later.append(event)
        if self._scheduled or self.host_settles:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            self.settle()
            return
        self._scheduled = True
        loop.call_soon(self.settle)

    def settle(self) -> None:
        """Tell the events held by :meth:`later` now (nothing when none are held)."""
        self._scheduled = False
        while self._later:
            held, self._later = self._later, []
            for event in held:
                for call in self._calls:
                    try:
                        call(event)
                    except Exception as exc:
                        self.failed(call, exc, event)

    __call__ = emit  # a core's ``emit``: false while nobody listens


def attach_all(host: Host, observers: Iterable[Observer]) -> list[Observer]:
    """Attach ``observers`` to ``host`` (its :class:`Observers`); the list attached."""
    return host.observers.attach(host, observers)


def close_all(observers: Iterable[Observer]) -> None:
    """Close in the reverse order of attaching (the last attached may use the first)."""
    for observer in reversed(list(observers)):
        observer.close()


class Listener:
    """An observer that calls ``call`` with each event of the given types (all: none given)."""

    def __init__(self, call: Callable[[Event], None], *types: type) -> None:
        self.call = call
        self.types = types

    def attach(self, host: Host) -> None:
        """Nothing to start."""

    def on_event(self, event: Event) -> None:
        if not self.types or isinstance(event, self.types):
            self.call(event)

    def close(self) -> None:
        """Nothing to finish."""


def listen(host: Host, call: Callable[[Event], None], *types: type) -> Listener:
    """Attach a :class:`Listener` of ``types`` to ``host``; it, for ``detach``."""
    listener = Listener(call, *types)
    host.observers.attach(host, [listener])
    return listener
