"""The executive's side of the people around the robot: operator commands and alerts.

Commands from the console, ``frog-bt ctl`` or an acknowledgement link are queued
(:meth:`Staff.submit`, from any task) and applied at the next tick boundary
(:meth:`Staff.before_tick`, each through :meth:`Staff.apply`): tree commands through
:meth:`~frog_bt.engine.core.Core.command`, ``ack_alert`` to the alert book; both are
recorded with their answer. A command the executive cannot apply within ``APPLY_WITHIN``
seconds (the tree does not tick while rosbridge is unreachable) is refused and changes
nothing.

At the end of each tick (:meth:`Staff.after_tick`, the core's ``after_tick``: before the
observers hear the tick, so that a recording keeps a tick's alert changes with it) the
alert conditions are checked against what the executive knows now
(:class:`~frog_bt.runtime.alerts.Facts`).

The host is the online executive or a replay (:mod:`frog_bt.offline.replay`), which
holds a :class:`Staff` of its own and calls :meth:`Staff.apply`, :meth:`Staff.after_tick`,
:meth:`Staff.links_changed` and :meth:`Staff.restore` where the recording says the
executive did: the same alert book, the same answers.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

from py_trees.common import Status

from frog_bt.engine.operator import Answer, Command
from frog_bt.i18n import Msg
from frog_bt.model import keys
from frog_bt.model.channels import Carried, CarriedIncident
from frog_bt.model.events import Event, OperatorDone
from frog_bt.model.help import Help
from frog_bt.model.links import LinkStatus
from frog_bt.model.outcomes import Incident, IncidentKind, TourState
from frog_bt.runtime.alerts import AlertBook, Facts

if TYPE_CHECKING:
    from frog_bt.clock import Clock
    from frog_bt.config import Site
    from frog_bt.engine.core import Core
    from frog_bt.model.links import Links
    from frog_bt.runtime.decisions import Decisions

log = logging.getLogger(__name__)
if log.level == logging.NOTSET:  # a person steered the robot: at INFO, always in the log
    log.setLevel(logging.INFO)
REMEMBER_ACKS = 120.0  # project seconds after start-up in which a restored ack applies
APPLY_WITHIN = 5.0  # wall seconds a queued command waits for a tick before it is refused


@dataclass(slots=True)
class Queued:
    command: Command
    alert_id: str
    answer: asyncio.Future[Answer]
    by: str = ""  # who sent it: console, ctl, link (recorded with the answer)
    occurrence: str | None = None  # ack_alert from a link: only this raise of the alert
    ready: Callable[[], bool] | None = None  # held in the queue until this holds
    help: Help | None = None  # done_by_hand in a rehearsal: the request it answers


class StaffHost(Protocol):
    """What :class:`Staff` works on: the executive, or a replay of one."""

    @property
    def site(self) -> Site: ...
    @property
    def clock(self) -> Clock: ...
    @property
    def core(self) -> Core: ...  # the core running now (a reload replaces it)
    @property
    def links(self) -> Links | None: ...  # each link's state as last checked (None: unknown)

    def emit(self, event: Event) -> None: ...
    def wake(self) -> None: ...


@dataclass
class Staff:
    executive: StaffHost
    book: AlertBook = field(init=False)
    link_since: dict[str, tuple[LinkStatus, float]] = field(default_factory=dict)
    _queue: list[Queued] = field(default_factory=list)
    _seeking_since: float | None = None
    remembered_acks: set[str] = field(default_factory=set)  # acknowledged before a restart
    _remember_until: float | None = None
    _pause_ran_out: bool = False
    _touring: bool = False
    # a rehearsal's hands (frog-bt demo): before ``done_by_hand`` is checked, the
    # simulated robot is put where a person would have put it
    by_hand: Callable[[Help], None] | None = None

    def __post_init__(self) -> None:
        site = self.executive.site
        self.book = AlertBook(site.alerts, language=site.language, names=site.name)

    # ------------------------------------------------------------ commands

    async def submit(
        self, command: Command, alert_id: str = "", by: str = "", occurrence: str | None = None
    ) -> Answer:
        """Queue ``command`` (sent ``by`` console, ctl or an acknowledgement link); its
        answer once applied at the next tick (or refused). ``occurrence``: ``ack_alert``
        acknowledges only that raise of the alert (an acknowledgement link's).
        ``done_by_hand`` in a rehearsal first does the step (:attr:`by_hand`), and is
        applied at the first tick that sees it done, before the tree hears of it."""
        answer: asyncio.Future[Answer] = asyncio.get_running_loop().create_future()
        queued = Queued(command, alert_id, answer, by, occurrence)
        help_ = self.executive.core.board.get(keys.HELP)
        if command is Command.DONE_BY_HAND and self.by_hand is not None and help_ is not None:
            self.by_hand(help_)
            queued.help = help_
            queued.ready = lambda: self.executive.core.operator.not_done(help_) is None
        self._queue.append(queued)
        self.executive.wake()
        try:
            return await asyncio.wait_for(asyncio.shield(answer), APPLY_WITHIN)
        except TimeoutError:
            if queued in self._queue:
                self._queue.remove(queued)
                return Answer(
                    False,
                    Msg(
                        "the executive is not ticking now (is the robot "
                        "reachable?): nothing was changed"
                    ),
                )
            return await answer  # applied meanwhile

    def before_tick(self) -> None:
        """Apply what was queued, in order, between two ticks."""
        queue, self._queue = self._queue, []
        for queued in queue:
            if queued.help is not None and self.executive.core.board.get(keys.HELP) is None:
                # the robot saw the step done (a fault gone) and went on by itself
                answer = Answer(True, Msg("going on: {done}", done=Msg(queued.help.about.by_hand)))
                log.info("operator %s: %s", queued.command, answer.text)
                queued.answer.set_result(answer)
                continue
            if queued.ready is not None and not queued.ready():
                self._queue.append(queued)  # a rehearsal's hands are still at work
                continue
            answer = self.apply(queued.command, queued.alert_id, queued.by, queued.occurrence)
            if not queued.answer.done():
                queued.answer.set_result(answer)

    def apply(
        self, command: Command, alert_id: str = "", by: str = "", occurrence: str | None = None
    ) -> Answer:
        """Apply one command now, between two ticks: ``ack_alert`` to the alert book,
        any other to the tree (:meth:`~frog_bt.engine.core.Core.command`); its answer,
        also told to the host's observers (the recording) and logged. ``occurrence``: the
        raise an acknowledgement link was made for (None: any, as from the console)."""
        core = self.executive.core
        if command is Command.ACK_ALERT:
            now = core.clock.now()
            answer = self._acknowledge(alert_id, occurrence, now)
            core.journal.note(f"operator: ack_alert {alert_id}: {answer.text}")
            self.executive.emit(
                OperatorDone(
                    now, core.ticks + 1, command.value, answer.ok, answer.text, alert_id, by=by
                )
            )
        else:
            answer = core.command(command, by=by)
        # a person steered the robot: always in the log (at INFO, the log's level)
        log.info("operator %s: %s%s", command, "" if answer.ok else "refused: ", answer.text)
        return answer

    def _acknowledge(self, alert_id: str, occurrence: str | None, now: float) -> Answer:
        seen = self.book.unacknowledged.get(alert_id)
        if seen is not None and occurrence not in (None, seen.occurrence):
            return Answer(False, Msg("alert {id} was raised again since that link", id=alert_id))
        ack = self.book.acknowledge(alert_id, now)
        if ack is None:
            return Answer(False, Msg("no alert {id} to acknowledge", id=repr(alert_id)))
        return Answer(True, Msg("alert {id} acknowledged", id=ack.id))

    def restore(self, decided: Decisions) -> None:
        """What staff decided before a restart holds again: out of service, a pause (its
        bound counts from the first tick), the help the robot waits for, the alerts
        acknowledged (acknowledged again when they come back, :data:`REMEMBER_ACKS`)."""
        board = self.executive.core.board
        board.set(keys.IN_SERVICE, decided.in_service)
        board.set(keys.PAUSED, decided.paused)
        board.set(keys.HELP_RESTORED, decided.help)
        self.remembered_acks = set(decided.acknowledged)

    def carried(self) -> Carried:
        """What the executive carries beside the tree into a rotated recording file."""
        board = self.executive.core.board
        active, shown, told_at = self.book.carried()
        return Carried(
            in_service=board.get(keys.IN_SERVICE) is not False,
            paused=bool(board.get(keys.PAUSED)),
            active=active,
            shown=shown,
            told_at=told_at,
            tour_incidents=[
                CarriedIncident(i.at, i.kind.value, i.text, i.subject)
                for i in self.executive.core.journal.tally.tour
            ],
            pause_ran_out=self._pause_ran_out,
        )

    def take_up(self, carried: Carried) -> None:
        """Hold what a rotated file's primer says the executive carried (replay)."""
        board = self.executive.core.board
        board.set(keys.IN_SERVICE, carried.in_service)
        board.set(keys.PAUSED, carried.paused)
        self.book.take_up(carried.active, carried.shown, carried.told_at)
        tour = []
        for i in carried.tour_incidents:
            with contextlib.suppress(ValueError):  # a kind this version does not know
                tour.append(Incident(i.at, IncidentKind(i.kind), i.text, i.subject))
        self.executive.core.journal.tally.take_up(tour)
        self._pause_ran_out = carried.pause_ran_out

    # ------------------------------------------------------------ links and alerts

    def links_changed(self, now: float) -> None:
        """Note when each link entered its state (the console shows for how long); on the
        project clock, so not before it has a time."""
        links = self.executive.links
        if not self.executive.clock.ready or links is None:
            return
        for name, state in links.items():
            seen = self.link_since.get(name)
            if seen is None or seen[0] is not state:
                self.link_since[name] = (state, now)

    def after_tick(self) -> None:
        self.check(self.executive.core.clock.now())

    def check(self, now: float) -> None:
        """Raise or clear alerts from what the executive knows now (also between ticks:
        a robot out of reach does not tick)."""
        self.links_changed(now)
        for alert in self.book.update(self.facts(now)):
            if alert.state == "raised" and alert.id in self.remembered_acks:
                self.remembered_acks.discard(alert.id)
                self.book.acknowledge(alert.id, now)  # acknowledged before a restart
        if self._remember_until is None:
            self._remember_until = now + REMEMBER_ACKS
        elif now >= self._remember_until:
            self.remembered_acks.clear()  # what did not come back since is forgotten

    def acknowledged_ids(self) -> frozenset[str]:
        """The alerts still up that a person has acknowledged (kept across a restart)."""
        book = self.book
        return frozenset(i for i in book.active if i not in book.unacknowledged)

    def facts(self, now: float) -> Facts:
        exe = self.executive
        core = exe.core
        board = core.board
        touring = board.get(keys.TOUR_STATE) is TourState.STARTED
        if touring and not self._touring:  # a new tour: its one-offs start afresh
            self._pause_ran_out = False
        self._touring = touring
        if core.pause_ran_out is not None:
            self._pause_ran_out = True
        seeking = any(n.status is Status.RUNNING for n in core.seekers)
        if seeking and self._seeking_since is None:
            self._seeking_since = now
        elif not seeking:
            self._seeking_since = None
        site = exe.site
        diagnostics = board.get(keys.DIAGNOSTICS)
        fresh = (
            diagnostics.value
            if diagnostics is not None and diagnostics.age(now) <= site.safety.diagnostics_max_age
            else None
        )
        gave_up = board.get(keys.GAVE_UP)
        rosbridge = self.link_since.get("rosbridge")
        frontend = self.link_since.get("frontend")
        return Facts(
            now=now,
            battery=fresh.battery if fresh is not None else None,
            faults=tuple(fresh.faults) if fresh is not None else (),
            rosbridge_down_since=(
                rosbridge[1]
                if rosbridge is not None and rosbridge[0] is not LinkStatus.CONNECTED
                else None
            ),
            frontend_silent_since=(
                frontend[1] if frontend is not None and frontend[0] is LinkStatus.SILENT else None
            ),
            seeking_since=self._seeking_since,
            gave_up=gave_up.text if gave_up is not None else "",
            help=board.get(keys.HELP),
            stops_given_up=tuple(core.journal.tally.stops_given_up()),  # until the next tour
            pause_ran_out=self._pause_ran_out,
            internal_errors=tuple(
                (seen.where, seen.count, seen.error) for seen in core.faults.repeated(now)
            ),
        )
