"""The taps of telemetry: cheap appends of plain values on the tick path (no rerun here).

:class:`Rows` is attached to a :class:`~frog_bt.engine.core.Core`'s taps. Each tap
only appends a tuple stamped with the tick it belongs to and the project-clock
time; the tick tap also records the tree's statuses when they changed, the new
decision notes and the engagement meter/decision from the blackboard. The
writer (:mod:`frog_bt.live.telemetry.writer`) takes the rows in batches
(:meth:`Rows.drain`) and does all formatting and logging.

A row's ``tick`` is the tick that consumes or produces it: inputs that arrive
after tick N, and commands sent while tick N+1 runs, belong to tick N+1, whose
statuses are recorded when it ends. So at tick N the viewer shows what the
tree saw, what it sent and where it ended. Rows that arrive before the clock
has a time (sim time before the first ``/clock``) take the time of the first
tick.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import py_trees

from frog_bt.live.telemetry.layout import TreeIndex
from frog_bt.model import keys
from frog_bt.model.events import (
    AlertChanged,
    Doubted,
    Event,
    Faulted,
    FrontendIn,
    FrontendOut,
    OperatorDone,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.key import Key
from frog_bt.model.outcomes import IncidentKind, Level
from frog_bt.model.wire import INPUTS

if TYPE_CHECKING:
    from frog_bt.config import Site
    from frog_bt.engine.core import Core
    from frog_bt.engine.journal import Journal, Note
    from frog_bt.runtime.observer import Host

Status = py_trees.common.Status
BOARD_KEYS: tuple[Key[Any], ...] = (
    keys.ENGAGEMENT_METER,
    keys.ENGAGEMENT_DECISION,
    keys.TARGET,  # a stop's lane: reached (the POI driven to when a drive succeeds)
)
SKIPPED = keys.SKIPPED.name  # a stop's lane: skipped (from the journal's incidents)
LEFT = frozenset({IncidentKind.STOP_SKIPPED, IncidentKind.STOP_LEFT})
_status = operator.attrgetter("status")
# A status as a small int in the rows (an int pickles at a fraction of an enum's cost, and
# a tuple of ints is dropped from the collector's books): its index here.
CODES = {
    s: i for i, s in enumerate((Status.RUNNING, Status.SUCCESS, Status.FAILURE, Status.INVALID))
}
STATES = tuple(s.name for s in CODES)  # code -> the name a status lane shows
Behaviour = py_trees.behaviour.Behaviour


@dataclass(slots=True)
class Batch:
    """Rows taken by the writer, oldest first. Each row starts with ``(tick, t)``."""

    poses: list[tuple[int, float, float, float, float]] = field(default_factory=list)  # x y yaw
    inputs: list[tuple[int, float, str, Any]] = field(default_factory=list)  # role, value
    outputs: list[tuple[int, float, str, str, Any]] = field(default_factory=list)
    # ^ side ("ros" | "frontend"), channel (topic | message type), payload
    events: list[tuple[int, float, str, Any]] = field(default_factory=list)  # type, message
    statuses: list[tuple[int, float, tuple[tuple[int, int], ...]]] = field(default_factory=list)
    # ^ the nodes whose status changed in that tick: (pre-order number, CODES[status])
    notes: list[tuple[int, float, str, Level]] = field(default_factory=list)
    blackboard: list[tuple[int, float, str, Any]] = field(default_factory=list)  # key, value
    marks: list[tuple[int, float, str, str, str]] = field(default_factory=list)
    # ^ bookmarks: kind ("staff" | "doubted" | "fault"), level, text

    def columns(self) -> tuple[list[Any], ...]:
        """The lists of rows, in field order (pickled as such for another process: no
        dataclass state to build per batch)."""
        return (
            self.poses,
            self.inputs,
            self.outputs,
            self.events,
            self.statuses,
            self.notes,
            self.blackboard,
            self.marks,
        )

    def extend(self, later: Batch) -> None:
        """Append the rows of a later batch (a writer merging batches, see
        :mod:`frog_bt.live.telemetry.process`)."""
        for rows, more in zip(self.columns(), later.columns(), strict=True):
            rows.extend(more)

    def restamp(self, t: float) -> None:
        """Give rows that arrived before the clock had a time (NaN) the time ``t``."""
        for rows in self._stamped():
            rows[:] = [(r[0], t, *r[2:]) if math.isnan(r[1]) else r for r in rows]

    def drop_unstamped(self) -> None:
        """Drop rows that still have no time (the clock never got one)."""
        for rows in self._stamped():
            rows[:] = [r for r in rows if not math.isnan(r[1])]

    def _stamped(self) -> tuple[list[tuple[Any, ...]], ...]:
        """The rows stamped with the time: ``(tick, t, ...)``."""
        return (self.poses, self.inputs, self.outputs, self.events, self.marks)

    def __len__(self) -> int:
        return sum(map(len, self.columns()))


class Rows:
    """Buffers rows from a core's taps until :meth:`drain`; calls ``on_full`` every
    ``batch_ticks`` ticks so the owner can write them out."""

    def __init__(
        self,
        site: Site,
        index: TreeIndex,
        *,
        batch_ticks: int = 50,
        on_full: Callable[[], None] | None = None,
    ) -> None:
        self.index = index
        self.roles = {site.topic(role): role for role in INPUTS}
        self.batch = Batch()
        self.batch_ticks = batch_ticks
        self.on_full = on_full
        self.host: Host | None = None
        self.raw_inputs = False  # keep inputs as received (msgspec.Raw), for another process
        self._behaviours = list(index.behaviours)
        self._position = {b: i for i, b in enumerate(self._behaviours)}  # by identity
        self._current: list[Status | None] = [None] * len(self._behaviours)
        self._scan_all = True  # read every node's status at the next tick
        self._last_note: Note | None = None
        self._journal: Journal | None = None
        self._incidents = 0  # incidents of that journal already seen
        self._blackboard: dict[str, Any] = {}
        self._ticks_since_drain = 0
        self._unstamped = False
        self._pending: list[tuple[Core, int, float, list[Behaviour], list[Status]]] = []

    def attach(self, host: Host) -> None:
        """Follow ``host``'s events (its core now, whichever that is)."""
        self.host = host

    def reindex(self, index: TreeIndex) -> None:
        """Follow another tree (a reload): its nodes, every status read afresh."""
        self.index = index
        self._behaviours = list(index.behaviours)
        self._position = {b: i for i, b in enumerate(self._behaviours)}
        self._current = [None] * len(self._behaviours)
        self._scan_all = True

    def detach(self) -> None:
        """Stop following (after close nothing more is buffered)."""
        self.host = None

    @property
    def core(self) -> Core | None:
        return self.host.core if self.host is not None else None

    def on_event(self, event: Event) -> None:
        """One event of the host: a row for it, or the tree's changes after a tick."""
        match event:
            case RobotInput():
                self.ros_in(event)
            case Ticked():
                core = self.core
                if core is not None:
                    self.tick(core)
            case RobotCommand():
                self.ros_out(event)
            case FrontendOut():
                self.frontend_out(event)
            case FrontendIn():
                self.frontend_in(event)
            case OperatorDone() | AlertChanged() | Doubted() | Faulted():
                self.mark(event)

    def mark(self, event: Event) -> None:
        """A bookmark: staff acted (a command, an alert raised for help, acknowledged), a
        robot's answer was not believed, or the executive's own code failed."""
        stamp = self._stamp(event.t)
        if stamp is None:
            return
        if isinstance(event, OperatorDone):
            by = f" ({event.by})" if event.by else ""
            word = "done" if event.ok else "refused"
            row = ("staff", "INFO" if event.ok else "WARN", f"{event.command}{by}: {word}")
        elif isinstance(event, AlertChanged):
            alert = event.alert
            row = (
                "staff",
                "WARN" if alert.state == "raised" else "INFO",
                f"alert {alert.kind} {alert.state}: {alert.text}",
            )
        elif isinstance(event, Doubted):
            row = ("doubted", "WARN", f"/FROG_response {event.code} not believed: {event.why}")
        elif isinstance(event, Faulted):
            row = ("fault", "ERROR", f"{event.where}: {event.what} failed ({event.count}x)")
        else:
            return
        self.batch.marks.append((*stamp, *row))

    def _stamp(self, t: float) -> tuple[int, float] | None:
        """(tick, t) for a row arriving now; None when detached. Before the clock has a
        time (sim time before the first ``/clock``) the time is NaN until the first tick."""
        core = self.core
        if core is None:
            return None
        if not core.clock.ready:
            self._unstamped = True
            return core.ticks + 1, math.nan
        return core.ticks + 1, t

    # ------------------------------------------------------------ events

    def ros_in(self, event: RobotInput) -> None:
        stamp = self._stamp(event.t)
        if stamp is None or event.value is None:
            return
        value: Any = event.value
        role = self.roles.get(event.topic)
        if role == "pose":
            self.batch.poses.append((*stamp, value.x, value.y, value.yaw))
        elif role is not None:
            # Another process decodes the bytes again: cheaper to hand over than the values.
            raw = event.raw if self.raw_inputs else None
            self.batch.inputs.append((*stamp, role, value if raw is None else raw))

    def ros_out(self, out: RobotCommand) -> None:
        stamp = self._stamp(out.t)
        if stamp is not None:
            self.batch.outputs.append((*stamp, "ros", out.topic, out))

    def frontend_out(self, event: FrontendOut) -> None:
        stamp = self._stamp(event.t)
        if stamp is not None:
            message = event.message
            self.batch.outputs.append((*stamp, "frontend", message.type, message))

    def frontend_in(self, event: FrontendIn) -> None:
        stamp = self._stamp(event.t)
        if stamp is not None:
            message = event.message
            self.batch.events.append((*stamp, message.type, message))

    def tick(self, core: Core) -> None:
        """After each tick (the host tells it once the tick's callback is over, before the
        next tick: :meth:`~frog_bt.runtime.observer.Observers.later`): the statuses of the
        nodes it touched, then :meth:`settle`."""
        if not core.clock.ready:
            self._scan_all = True  # this tick's changes are not followed
            return
        touched = getattr(core, "told", None)
        if self._scan_all or touched is None:
            nodes = self._behaviours
            self._scan_all = touched is None
        else:
            # Only the nodes the tick reached or stopped can have changed (Core.touched):
            # the cost follows the active path, not the size of the tour.
            nodes = touched
        self._pending.append((core, core.ticks, core.clock.now(), nodes, [*map(_status, nodes)]))
        self.settle()

    def settle(self) -> None:
        """The rows of the ticks taken since the last call: the statuses that changed (only
        those: a row is not a copy of the tree), the new notes, the engagement keys."""
        pending, self._pending = self._pending, []
        batch, current, position = self.batch, self._current, self._position
        for core, tick, t, nodes, statuses in pending:
            if self._unstamped:
                batch.restamp(t)
                self._unstamped = False
            changes: list[tuple[int, int]] = []
            for node, status in zip(nodes, statuses, strict=True):
                i = position.get(node)
                if i is not None and current[i] is not status:
                    current[i] = status
                    changes.append((i, CODES[status]))
            if changes:
                batch.statuses.append((tick, t, tuple(changes)))
            notes = core.journal.notes
            if notes and notes[-1] is not self._last_note:
                i = len(notes) - 1
                while i >= 0 and notes[i] is not self._last_note:
                    i -= 1
                batch.notes.extend((tick, n.at, n.text, n.level) for n in notes[i + 1 :])
                self._last_note = notes[-1]
            journal = core.journal
            if journal is not self._journal:  # another core (a reload): its own journal
                self._journal, self._incidents = journal, 0
            if journal.incident_total != self._incidents:
                # A stop given up on: its lane says skipped. Read off the incidents, not
                # the blackboard: /skipped is written and cleared (the next stop's scope)
                # within one tick.
                for incident in journal.incidents_since(self._incidents):
                    if incident.kind in LEFT and incident.subject:
                        batch.blackboard.append((tick, incident.at, SKIPPED, incident.subject))
                self._incidents = journal.incident_total
            for key in BOARD_KEYS:
                value = core.board.get(key)
                if value is not self._blackboard.get(key.name):
                    self._blackboard[key.name] = value
                    batch.blackboard.append((tick, t, key.name, value))
            self._ticks_since_drain += 1
        if self._ticks_since_drain >= self.batch_ticks and self.on_full is not None:
            self.on_full()

    # ------------------------------------------------------------ the writer's side

    def drain(self) -> Batch:
        """The rows buffered so far; the buffer starts afresh."""
        if self._pending:
            self.settle()
        batch, self.batch = self.batch, Batch()
        self._ticks_since_drain = 0
        if self._unstamped:  # drained before the first tick with a time
            core = self.core
            if core is not None and core.clock.ready:
                batch.restamp(core.clock.now())
            batch.drop_unstamped()
            self._unstamped = False
        return batch
