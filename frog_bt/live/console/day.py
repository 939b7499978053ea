"""The day so far, for the console: tours started, completed and aborted, visitors
recruited, stops skipped, and the last tours in one line each.

An :class:`~frog_bt.runtime.observer.Observer`: every figure is read from the one count of
tours (:class:`~frog_bt.model.ledger.TourLedger`, fed each event; a tour the executive
resumed is carried on from its checkpoint, :mod:`frog_bt.runtime.resuming`), the same
fold the demo summary, the status line and the report read; it keeps no more than
:data:`LAST_TOURS` lines.
"""

from __future__ import annotations

from collections import deque
from datetime import datetime
from typing import TYPE_CHECKING

from frog_bt.i18n import N_, Msg, say
from frog_bt.model.events import Event, FrontendOut
from frog_bt.model.frontend import Tour
from frog_bt.model.outcomes import TourState
from frog_bt.model.tours import TourPlan, TourRow
from frog_bt.runtime.resuming import ResumingLedger

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
        self.ledger = ResumingLedger(TourPlan())  # the site's plan once attached
        self.last: deque[str] = deque(maxlen=LAST_TOURS)
        self._host: Host | None = None

    def attach(self, host: Host) -> None:
        self._host = host
        self.ledger = ResumingLedger(host.site.tour_plan())
        self.ledger.attach(host)

    def on_event(self, event: Event) -> None:
        before = self.ledger.current
        self.ledger.on_event(event)
        match event:
            case FrontendOut(t=t, message=Tour(state=state)) if state != TourState.STARTED:
                if before is not None and before.ended:
                    self._line(t, before)
            case _:
                pass

    def close(self) -> None:
        """Nothing to finish."""

    @property
    def started(self) -> int:
        return self.ledger.started

    @property
    def completed(self) -> int:
        return self.ledger.completed

    @property
    def aborted(self) -> int:
        return self.ledger.aborted

    @property
    def visitors(self) -> int:
        """Who said yes to a tour today."""
        return self.ledger.said_yes

    @property
    def skipped(self) -> int:
        """Stops skipped today: left by the operator, given up, or their visitor lost
        (the report's ``stops_skipped`` with those reasons)."""
        return self.ledger.skipped()

    def _local(self, t: float) -> str:
        assert self._host is not None
        return datetime.fromtimestamp(t, self._host.clock.tz).strftime("%H:%M")

    def _line(self, t: float, row: TourRow) -> None:
        """The line of a tour that just ended or aborted."""
        start = self._local(row.started) + "-" if row.started else ""
        parts = [say(Msg("{n} stops", n=len(row.reached)), self.language)]
        left = row.left(self.ledger.plan.content)
        if left:
            parts.append(say(Msg("skipped {stops}", stops=", ".join(left)), self.language))
        if row.reason:
            parts.append(say(reason_words(row.reason), self.language))
        when, said = start + self._local(t), "; ".join(parts)
        line = (
            Msg("{when} tour ended: {parts}", when=when, parts=said)
            if row.ended == TourState.ENDED
            else Msg("{when} tour aborted: {parts}", when=when, parts=said)
        )
        self.last.appendleft(say(line, self.language))
