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

from frog_bt.engine.tally import LEFT_STOPS
from frog_bt.i18n import N_, Msg, say
from frog_bt.model.events import Event, FrontendIn, FrontendOut
from frog_bt.model.frontend import FrontendMessage, StartPoi, Tour, UserPositive

if TYPE_CHECKING:
    from frog_bt.runtime.observer import Host

LAST_TOURS = 10
# a tour's reason (the words of the tour message) as staff say it, by how it starts
REASONS = (
    ("operator", N_("sent home by staff")),
    ("battery", N_("battery low")),
    ("electronics fault", N_("electronics fault")),
    ("paused longer", N_("paused too long")),
)


def reason_words(reason: str) -> Msg | str:
    """Why a tour ended early, in words staff use (a reason not known: as it was given)."""
    return next((Msg(words) for start, words in REASONS if reason.startswith(start)), reason)


class Day:
    """``language``: the site's, which the day's lines are written in."""

    def __init__(self, language: str = "en") -> None:
        self.language = language
        self.started = 0
        self.completed = 0
        self.aborted = 0
        self.visitors = 0  # who said yes to a tour
        self.last: deque[str] = deque(maxlen=LAST_TOURS)
        self._host: Host | None = None
        self._tour_start: float | None = None
        self._stops: list[str] = []

    def attach(self, host: Host) -> None:
        self._host = host

    def on_event(self, event: Event) -> None:
        match event:
            case FrontendOut(t=t, message=message):
                self._out(t, message)
            case FrontendIn(message=UserPositive()):
                self.visitors += 1

    def close(self) -> None:
        """Nothing to finish."""

    def _local(self, t: float) -> str:
        assert self._host is not None
        return datetime.fromtimestamp(t, self._host.clock.tz).strftime("%H:%M")

    @property
    def skipped(self) -> int:
        """Stops skipped or left today (the one tally's)."""
        if self._host is None:
            return 0
        return self._host.core.journal.tally.count(*LEFT_STOPS)

    def _out(self, t: float, message: FrontendMessage) -> None:
        if isinstance(message, StartPoi) and message.part == "a":
            self._stops.append(message.poi)
        elif isinstance(message, Tour):
            if message.state == "started":
                self.started += 1
                self._tour_start, self._stops = t, []
                return
            if message.state == "ended":
                self.completed += 1
            else:
                self.aborted += 1
            start = self._local(self._tour_start) + "-" if self._tour_start else ""
            parts = [say(Msg("{n} stops", n=len(self._stops)), self.language)]
            left = self._host.core.journal.tally.stops_left() if self._host else []
            if left:
                parts.append(say(Msg("skipped {stops}", stops=", ".join(left)), self.language))
            if message.reason:
                parts.append(say(reason_words(message.reason), self.language))
            when, said = start + self._local(t), "; ".join(parts)
            line = (
                Msg("{when} tour ended: {parts}", when=when, parts=said)
                if message.state == "ended"
                else Msg("{when} tour aborted: {parts}", when=when, parts=said)
            )
            self.last.appendleft(say(line, self.language))
            self._tour_start = None
