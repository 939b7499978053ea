"""The shift so far, and its handover to the next one (``staff.handover``).

:class:`Shift` is an :class:`~frog_bt.runtime.observer.Observer` of the executive. It
counts the tours (started, completed, ended early) with the one count of tours
(:class:`~frog_bt.model.ledger.TourLedger`, fed each event: the console's day's numbers,
for the shift's span), and reads the operator commands (who answered a help request, who
put the robot out of service and back) and, after each tick, the board's ``help`` and
``in_service`` (when a help request began and ended, the out-of-service periods). At
each time of ``staff.handover`` (local, the site's clock; project time, so sim time in a
rehearsal) — looked at after every tick and by the console between ticks
(:meth:`Shift.check`, a robot out of reach does not tick) — and when someone asks
(:meth:`Shift.hand_over`), it composes a :class:`~frog_bt.live.console.handover.Handover`
of what it saw since the last one, plus what is still open (the alerts up, what the
robot waits for), gives it to ``tell`` (the webhooks) and keeps it (:attr:`Shift.last`,
the page's *Relevo*). A help request or an out-of-service period still open is carried
into the next shift.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from datetime import datetime, time, timedelta
from typing import TYPE_CHECKING

from frog_bt.i18n import Msg
from frog_bt.live.console.handover import Asked, Handover, OpenAlert, Period, who
from frog_bt.model import keys
from frog_bt.model.events import Event, OperatorDone, Ticked
from frog_bt.model.links import LinkStatus
from frog_bt.model.tours import TourPlan
from frog_bt.runtime.resuming import ResumingLedger

if TYPE_CHECKING:
    from frog_bt.model.channels import Alert
    from frog_bt.runtime.observer import Host

__all__ = ["Shift", "next_time"]

log = logging.getLogger(__name__)
if log.level == logging.NOTSET:  # a shift handed over: at INFO, always in the log
    log.setLevel(logging.INFO)
KEPT = 50  # help requests and out-of-service periods kept per shift (the latest)


def next_time(now: float, times: list[time], tz: object) -> float | None:
    """The first of ``times`` (local, in ``tz``) strictly after ``now`` (epoch seconds);
    None when there are none."""
    if not times:
        return None
    today = datetime.fromtimestamp(now, tz).date()  # type: ignore[arg-type]
    for day in (today, today + timedelta(days=1)):
        for at in times:
            when = datetime.combine(day, at, tz).timestamp()  # type: ignore[arg-type]
            if when > now:
                return when
    return None  # unreachable: tomorrow's first is after now


class Shift:
    """``times``: ``staff.handover``; ``alerts``: the alert book's alerts up now, with
    whether a person has acknowledged each; ``tell``: where a handover goes (the
    webhooks), called once per handover."""

    def __init__(
        self,
        times: list[time],
        alerts: Callable[[], list[tuple[Alert, bool]]],
        tell: Callable[[Handover], None] | None = None,
    ) -> None:
        self.times = times
        self.alerts = alerts
        self.tell = tell
        self.last: Handover | None = None
        self.since: float | None = None  # the shift's start (the console's, or the last handover)
        self.due: float | None = None  # the next scheduled handover
        self.ledger = ResumingLedger(TourPlan())  # the one count of tours: the site's once attached
        self._before = self._counts()  # the ledger's counts when this shift began
        self.asked: list[Asked] = []
        self.periods: list[Period] = []
        self._host: Host | None = None
        self._help_since: float | None = None  # the help request open now
        self._answer: tuple[str, str] | None = None  # (command, by) answering it
        self._off_by = ""  # who put it out of service / back, last
        self._on_by = ""

    def attach(self, host: Host) -> None:
        self._host = host
        self.ledger = ResumingLedger(host.site.tour_plan())
        self.ledger.attach(host)
        self._before = self._counts()

    def _counts(self) -> dict[str, int]:
        ledger = self.ledger
        return {
            "started": ledger.started,
            "completed": ledger.completed,
            "aborted": ledger.aborted,
        }

    @property
    def tours(self) -> dict[str, int]:
        """The tours of this shift: started, completed and ended early since it began
        (the console's day's counts, less those at the last handover)."""
        now = self._counts()
        return {kind: now[kind] - self._before[kind] for kind in now}

    def close(self) -> None:
        """Nothing to finish."""

    # ------------------------------------------------------------ what it sees

    def on_event(self, event: Event) -> None:
        self.ledger.on_event(event)
        match event:
            case Ticked(t=t):
                self._look(t)
                self.check(t)
            case OperatorDone(ok=True):
                self._done(event)
            case _:
                pass

    def _done(self, event: OperatorDone) -> None:
        if event.command in ("retry", "done_by_hand") and self._help_since is not None:
            self._answer = (event.command, event.by)
        elif event.command == "service_off":
            self._off_by = event.by
        elif event.command == "service_on":
            self._on_by = event.by

    def _look(self, now: float) -> None:
        """After a tick: a help request begun or over, out of service or back."""
        if self.since is None:
            self.since = now
        assert self._host is not None
        board = self._host.core.board
        help_ = board.get(keys.HELP)
        since = help_.since if help_ is not None else None
        if since != self._help_since:
            if self._help_since is not None and self.asked:
                over = self.asked[-1]
                command, by = self._answer or ("", "")
                over.answered, over.by, over.answer = now, by, command
            if help_ is not None:
                self.asked.append(Asked(help_.about.value, help_.what, help_.since))
                del self.asked[:-KEPT]
            self._help_since, self._answer = since, None
        off = board.get(keys.IN_SERVICE) is False
        open_ = self.periods[-1] if self.periods and self.periods[-1].until is None else None
        if off and open_ is None:
            self.periods.append(Period(now, by=self._off_by))
            del self.periods[:-KEPT]
        elif not off and open_ is not None:
            open_.until, open_.back_by = now, self._on_by

    # ------------------------------------------------------------ handing over

    def check(self, now: float) -> Handover | None:
        """The scheduled handover when one is due at ``now`` (project clock); None else."""
        if self._host is None or not self.times:
            return None
        if self.due is None:
            self.due = next_time(now, self.times, self._host.clock.tz)
            return None
        if now < self.due:
            return None
        self.due = next_time(now, self.times, self._host.clock.tz)
        return self.hand_over(now)

    def hand_over(self, now: float, by: str = "") -> Handover:
        """Compose the handover of the shift up to ``now``, tell it, keep it, and start
        the next shift (what is still open carried into it). ``by``: who asked ("":
        the schedule)."""
        waiting = self._waiting(now)
        handover = Handover(
            at=now,
            since=self.since if self.since is not None else now,
            asked_by=by,
            tours=self.tours,
            asked=tuple(
                Asked(a.about, a.what, a.since, a.answered, a.by, a.answer) for a in self.asked
            ),
            alerts=tuple(
                OpenAlert(a.id, a.kind, a.text, a.since, seen) for a, seen in self.alerts()
            ),
            out_of_service=tuple(Period(p.since, p.until, p.by, p.back_by) for p in self.periods),
            waiting=tuple(waiting),
        )
        self.last = handover
        self.since = now
        self._before = self._counts()
        self.asked = [a for a in self.asked if a.answered is None]
        self.periods = [p for p in self.periods if p.until is None]
        log.info(
            "shift handed over (%s): %d tours started, %d help requests, %d alerts open",
            "on schedule" if not by else f"asked by {who(by)}",
            handover.tours["started"],
            len(handover.asked),
            len(handover.alerts),
        )
        if self.tell is not None:
            self.tell(handover)
        return handover

    def _waiting(self, now: float) -> list[Msg]:
        """What the robot still waits for, in sentences."""
        out: list[Msg] = []
        if self._host is None:
            return out
        board = self._host.core.board
        help_ = board.get(keys.HELP)
        if help_ is not None:
            out.append(Msg("a person: {what}", what=Msg(help_.what)))
        if board.get(keys.PAUSED):
            out.append(Msg("Resume: it is paused"))
        if board.get(keys.IN_SERVICE) is False:
            out.append(Msg("Back in service: it is out of service"))
        unseen = sum(1 for _, seen in self.alerts() if not seen)
        if unseen:
            out.append(Msg("someone to mark {n} alerts seen", n=unseen))
        links = self._host.links
        if links is not None and links.rosbridge is not LinkStatus.CONNECTED:
            out.append(Msg("its link to the robot"))
        return out
