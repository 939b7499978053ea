"""The executive's side of the people around the robot: operator commands and alerts.

Commands from the console or ``frog-bt ctl`` are queued (:meth:`Staff.submit`, from any
task) and applied at the next tick boundary (:meth:`Staff.before_tick`): tree commands
through :meth:`~frog_bt.engine.core.Core.command` (recorded, replayed), ``ack_alert`` to
the alert book. A command the executive cannot apply within ``APPLY_WITHIN`` seconds
(the tree does not tick while rosbridge is unreachable) is refused and changes nothing.

After each tick (:meth:`Staff.after_tick`) the alert conditions are checked against what
the executive knows now (:class:`~frog_bt.runtime.alerts.Facts`).
"""

from __future__ import annotations

import asyncio
import logging
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from py_trees.common import Status

from frog_bt.engine.operator import Answer, Command
from frog_bt.i18n import Msg
from frog_bt.model import keys
from frog_bt.model.events import OperatorDone
from frog_bt.model.links import LinkStatus
from frog_bt.model.outcomes import TourState
from frog_bt.runtime.alerts import AlertBook, Facts

if TYPE_CHECKING:
    from frog_bt.runtime.executive import Executive

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


@dataclass
class Staff:
    executive: Executive
    book: AlertBook = field(init=False)
    link_since: dict[str, tuple[LinkStatus, float]] = field(default_factory=dict)
    _queue: list[Queued] = field(default_factory=list)
    _seeking_since: float | None = None
    remembered_acks: set[str] = field(default_factory=set)  # acknowledged before a restart
    _remember_until: float | None = None
    _pause_ran_out: bool = False
    _touring: bool = False

    def __post_init__(self) -> None:
        site = self.executive.site
        self.book = AlertBook(site.alerts, language=site.language, names=site.name)

    # ------------------------------------------------------------ commands

    async def submit(
        self, command: Command, alert_id: str = "", by: str = "", occurrence: str | None = None
    ) -> Answer:
        """Queue ``command`` (sent ``by`` console, ctl or an acknowledgement link); its
        answer once applied at the next tick (or refused). ``occurrence``: ``ack_alert``
        acknowledges only that raise of the alert (an acknowledgement link's)."""
        answer: asyncio.Future[Answer] = asyncio.get_running_loop().create_future()
        queued = Queued(command, alert_id, answer, by, occurrence)
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
        core = self.executive.core
        for queued in queue:
            if queued.command is Command.ACK_ALERT:
                now = core.clock.now()
                answer = self._acknowledge(queued, now)
                core.journal.note(f"operator: ack_alert {queued.alert_id}: {answer.text}")
                self.executive.emit(
                    OperatorDone(
                        now,
                        core.ticks + 1,
                        queued.command.value,
                        answer.ok,
                        answer.text,
                        queued.alert_id,
                        by=queued.by,
                    )
                )
            else:
                answer = core.command(queued.command, by=queued.by)
            # a person steered the robot: always in the log (at INFO, the log's level)
            log.info(
                "operator %s: %s%s", queued.command, "" if answer.ok else "refused: ", answer.text
            )
            if not queued.answer.done():
                queued.answer.set_result(answer)

    def _acknowledge(self, queued: Queued, now: float) -> Answer:
        seen = self.book.unacknowledged.get(queued.alert_id)
        if seen is not None and queued.occurrence not in (None, seen.occurrence):
            return Answer(
                False, Msg("alert {id} was raised again since that link", id=queued.alert_id)
            )
        ack = self.book.acknowledge(queued.alert_id, now)
        if ack is None:
            return Answer(False, Msg("no alert {id} to acknowledge", id=repr(queued.alert_id)))
        return Answer(True, Msg("alert {id} acknowledged", id=ack.id))

    # ------------------------------------------------------------ links and alerts

    def links_changed(self, now: float) -> None:
        """Note when each link entered its state (the console shows for how long); on the
        project clock, so not before it has a time."""
        if not self.executive.clock.ready:
            return
        for name, state in self.executive.links.items():
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
        )
