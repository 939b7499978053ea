"""The day so far, for the console: tours started, completed and aborted, visitors
recruited, stops skipped, and the last tours in one line each.

An :class:`~frog_bt.runtime.observer.Observer`: it counts what crosses the core (the ``tour``
messages to the front end, the visitors' yes, the incidents) and keeps no more than
:data:`LAST_TOURS` lines.
"""

from __future__ import annotations

from collections import deque
from datetime import datetime
from typing import TYPE_CHECKING

from frog_bt.model.frontend import FrontendMessage, StartPoi, Tour, UserPositive
from frog_bt.model.outcomes import IncidentKind

if TYPE_CHECKING:
    from frog_bt.engine.core import Core
    from frog_bt.runtime.observer import Host

LAST_TOURS = 10


class Day:
    def __init__(self) -> None:
        self.started = 0
        self.completed = 0
        self.aborted = 0
        self.visitors = 0  # who said yes to a tour
        self.skipped = 0  # stops skipped or left
        self.last: deque[str] = deque(maxlen=LAST_TOURS)
        self._core: Core | None = None
        self._tour_start: float | None = None
        self._stops: list[str] = []
        self._skipped_now: list[str] = []
        self._incidents_seen = 0

    def attach(self, host: Host) -> None:
        self._core = host.core
        host.taps.frontend_out.append(self._out)
        host.taps.frontend_in.append(self._in)
        host.taps.tick.append(self._tick)

    def close(self) -> None:
        """Nothing to finish."""

    def _local(self, t: float) -> str:
        assert self._core is not None
        return datetime.fromtimestamp(t, self._core.clock.tz).strftime("%H:%M")

    def _out(self, t: float, _type: str, message: FrontendMessage) -> None:
        if isinstance(message, StartPoi) and message.part == "a":
            self._stops.append(message.poi)
        elif isinstance(message, Tour):
            if message.state == "started":
                self.started += 1
                self._tour_start, self._stops, self._skipped_now = t, [], []
                return
            if message.state == "ended":
                self.completed += 1
            else:
                self.aborted += 1
            start = self._local(self._tour_start) + "-" if self._tour_start else ""
            parts = [f"{len(self._stops)} stops"]
            if self._skipped_now:
                parts.append(f"skipped {', '.join(self._skipped_now)}")
            if message.reason:
                parts.append(message.reason)
            self.last.appendleft(f"{start}{self._local(t)} tour {message.state}: "
                                 f"{'; '.join(parts)}")
            self._tour_start = None

    def _in(self, _t: float, _type: str, message: FrontendMessage) -> None:
        if isinstance(message, UserPositive):
            self.visitors += 1

    def _tick(self, core: Core) -> None:
        journal = core.journal
        new = journal.incidents_since(self._incidents_seen)
        self._incidents_seen = journal.incident_total
        for incident in new:
            if incident.kind in (IncidentKind.STOP_SKIPPED, IncidentKind.STOP_LEFT):
                self.skipped += 1
                self._skipped_now.append(incident.subject)
