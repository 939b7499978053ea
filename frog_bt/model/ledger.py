"""The one count of tours: a fold over the executive's events (:mod:`frog_bt.model.events`).

:class:`TourLedger` takes the events one at a time (:meth:`TourLedger.feed`, or
:func:`fold` over many) and keeps one :class:`~frog_bt.model.tours.TourRow` per tour: its
stops, goals, visitors, staff commands, help requests and outcome (the row and what a
stop's visit comes to, reached, played or skipped and why: :mod:`frog_bt.model.tours`).
Everyone who counts tours reads it: the console's day and shift, the status line, the
demo summary and the executive's outcome live; the report (through each file's events)
and ``frog-bt coverage`` (through a replay) offline. Pure: no clock, no I/O, no
configuration (the site's part of it comes in as a :class:`~frog_bt.model.tours.TourPlan`).

The stops counted are the tour's content stops (:attr:`TourPlan.content`).

Tours: a row opens at ``tour started``, or, when the fold begins inside a tour (a
restarted executive resuming one, a recording file opening in one, a console attached
mid-tour), at the first event (:attr:`TourRow.started` None; kept only when something of
a tour happens in it). A row closes at ``tour ended``, or, after ``tour aborted``, once
the robot has driven back and docked (that drive is the tour's too).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from frog_bt.maths.engagement import decide
from frog_bt.model.events import (
    AlertChanged,
    Doubted,
    Event,
    FrontendIn,
    FrontendOut,
    OperatorDone,
    RobotCommand,
    RobotInput,
)
from frog_bt.model.frontend import (
    AskTour,
    ContentDone,
    FinishPoi,
    StartPoi,
    Tour,
    UserNegative,
    UserPositive,
)
from frog_bt.model.help import HelpAnswer
from frog_bt.model.outcomes import (
    DiagnosticLevel,
    DockCommand,
    DockingState,
    FaceStream,
    TourState,
)
from frog_bt.model.ros import Diagnostics, FaceData, Pose
from frog_bt.model.tours import (
    LEFT,
    Fate,
    SkipWhy,
    StaffCommand,
    StopVisit,
    TourPlan,
    TourRow,
    skips,
)
from frog_bt.model.wire import SUCCEEDED, Response

__all__ = [  # the row types are re-exported: readers of the count import them from here too
    "LEFT",
    "Fate",
    "SkipWhy",
    "StaffCommand",
    "StopVisit",
    "TourLedger",
    "TourPlan",
    "TourRow",
    "fold",
    "skips",
    "step",
]

JUMP = 10.0  # metres: a pose step this long is a relocalisation, not a drive
SKIP = "skip"  # the operator command that leaves a stop (engine.operator.Command.SKIP)


class TourLedger:
    """The fold: :meth:`feed` one event at a time; :attr:`rows` every row opened,
    :attr:`tours` those that are tours. Also an observer (``attach``/``close`` do
    nothing), so a host can tell it events like any other."""

    def __init__(self, plan: TourPlan) -> None:
        self.plan = plan
        self.rows: list[TourRow] = []
        self.current: TourRow | None = None
        self.back: TourRow | None = None  # an aborted tour's row until the robot docks
        self.opening = True  # the row open began with the fold (no `tour started` seen)
        self.said_yes = 0  # invitations accepted, over all rows
        self.resumed = False  # a resumed tour was taken up (:meth:`resume`)
        self._roles = {topic: role for role, topic in plan.topics.items()}
        self._goal: str | None = None  # waypoint of the goal awaiting its response
        self._failed: str | None = None  # waypoint whose goal failed last
        self._approach = False
        self._dock: str | None = None
        self._dock_failed: str | None = None
        self._asked = False
        self._stream_on = False
        self._samples: list[tuple[float, float]] = []  # (t, level) while the stream is on
        self._pose: tuple[float, float] | None = None
        self._answer: tuple[StopVisit | None, str] | None = None  # the latest goal answer

    # ------------------------------------------------------------ reading

    @property
    def tours(self) -> list[TourRow]:
        """The rows that are tours (an opening row with nothing of a tour is not)."""
        return [r for r in self.rows if r.started is not None or r.of_a_tour()]

    @property
    def started(self) -> int:
        return sum(r.started is not None for r in self.rows)

    @property
    def completed(self) -> int:
        return sum(r.ended == TourState.ENDED for r in self.rows)

    @property
    def aborted(self) -> int:
        return sum(r.ended == TourState.ABORTED for r in self.rows)

    @property
    def latest(self) -> TourRow | None:
        """The tour open now, else the latest one."""
        tours = self.tours
        return tours[-1] if tours else None

    def skipped(self) -> int:
        """Stops left, over all tours (each tour's :meth:`TourRow.left`)."""
        return sum(len(r.left(self.plan.content)) for r in self.tours)

    # ------------------------------------------------------------ observer

    def attach(self, host: object) -> None:
        """Nothing to keep: the fold reads only the events."""

    def close(self) -> None:
        """Nothing to finish."""

    def on_event(self, event: Event) -> None:
        self.feed(event)

    # ------------------------------------------------------------ the fold

    def begin(self, t: float) -> None:
        """The fold starts at ``t`` (a recording's start): the opening row opens there."""
        if not self.rows:
            self._open(None, t)

    def resume(self, kept: TourRow | None) -> None:
        """The executive resumed a tour from its checkpoint, which kept the tour's row as
        it was then (``kept``; None: the checkpoint kept none): the row open now, begun
        with the fold, becomes that tour's (:meth:`TourRow.carried_on`), so the stops
        reached and skipped, the visitors, help and commands before the restart count as
        the report counts them over both executives' recordings. Once: later calls, and
        a call once a tour has started in this fold, change nothing."""
        if self.resumed:
            return
        self.resumed = True
        row = self.current
        if kept is None or row is None or not self.opening or row.started is not None:
            return
        joined = kept.carried_on(row)
        at = next(i for i, r in enumerate(self.rows) if r is row)
        self.rows[at] = self.current = joined
        self.said_yes += kept.accepted
        self.opening = False

    def feed(self, event: Event) -> None:
        """One event of the executive (those that tell nothing of tours are passed over)."""
        if not self.rows:
            self._open(None, event.t)
        match event:
            case FrontendOut(t=t, message=Tour() as tour):
                self._tour(t, tour)
            case FrontendOut(t=t, message=message):
                self._frontend_out(t, message)
            case FrontendIn(t=t, message=message):
                self._frontend_in(t, message)
            case RobotCommand():
                self._command(event)
            case RobotInput():
                self._input(event)
            case OperatorDone():
                self._operator(event)
            case AlertChanged(alert=alert):
                row = self.back or self.current
                if (
                    row is not None
                    and alert.state == "raised"
                    and alert.repeat == 0
                    and HelpAnswer.DONE_BY_HAND in alert.answers
                ):
                    row.help.append(alert.kind)
            case Doubted():
                self._doubted(event)
            case _:
                pass

    def _open(self, started: float | None, t: float) -> TourRow:
        row = TourRow(started, t0=t, t1=t)
        self.rows.append(row)
        self.current = row
        return row

    def _touch(self, t: float) -> TourRow | None:
        """The row open now (None between a tour's end and the next start), its last
        event moved to ``t``."""
        if self.current is not None:
            self.current.t1 = t
        return self.current

    def _visit(self) -> StopVisit | None:
        """The visit open now."""
        row = self.current
        if row is None or not row.stops or row.stops[-1].closed:
            return None
        return row.stops[-1]

    def _close_visit(self, moved_on: bool = False) -> None:
        """The visit open now is over; ``moved_on``: the tour went on elsewhere (a goal
        to another place), so a stop whose goals failed was given up."""
        visit = self._visit()
        if visit is None:
            return
        visit.closed = True
        if moved_on and not visit.arrived and visit.goals_failed and visit.skipped is None:
            visit.skipped = SkipWhy.NAVIGATION

    def _recruiting(self) -> None:
        """An approach or an invitation: a stop not yet played was left with its visitor."""
        row = self.current
        if row is not None and row.stops:
            last = row.stops[-1]
            if last.skipped is None and not last.played:
                last.skipped = SkipWhy.VISITOR_LOST
        self._close_visit()

    def _tour(self, t: float, message: Tour) -> None:
        state = TourState(message.state)
        if state is TourState.STARTED:
            row = self.current
            if row is not None and not self.opening:
                return  # said again (a resend taken anew): the same tour
            if row is not None and not row.of_a_tour():
                self.rows.remove(row)  # an opening with nothing of a tour
            self.back = None
            self._open(t, t)
            self.opening = False
            return
        row = self._touch(t)
        if row is not None:  # (None: said again after the tour's end)
            self._close_visit()
            row.ended, row.reason = state.value, message.reason
            if state is TourState.ABORTED:
                self.back = row  # the robot returns to its dock: still this tour's
        if row is not None and self.opening:
            # Before any `tour started` this may be the end of the tour before, said
            # again (a recording file opening just after it): what follows goes into a
            # new opening row, in case it is the open tour's.
            self._open(None, t)
        else:
            self.current, self.opening = None, False

    def _stop_visit(self, poi: str) -> StopVisit | None:
        row = self.current
        if row is None:
            return None
        for visit in reversed(row.stops):
            if visit.poi == poi:
                return visit
        return None

    def _frontend_out(self, t: float, message: object) -> None:
        row = self._touch(t)
        if row is None:
            return
        if isinstance(message, StartPoi):
            poi, part = message.poi, message.part
            visit = self._visit()
            if visit is None or visit.poi != poi or (part == "a" and visit.start is not None):
                self._close_visit()
                visit = StopVisit(poi, t)
                row.stops.append(visit)
            visit.face_stream = poi in self.plan.face_stops
            visit.waypoint = message.waypoint or poi
            visit.arrived = True  # its content starts: the arrival was believed
            if part == "a":
                visit.start = t
            if part not in visit.parts:
                visit.parts += part
            if part == "b":
                self._engagement(visit, t)
        elif isinstance(message, FinishPoi):
            found = self._stop_visit(message.poi)
            if found is not None:
                found.end = t
                if "b" not in found.parts:
                    self._engagement(found, t)
                if found is self._visit():
                    found.closed = True
        elif isinstance(message, AskTour):
            self._recruiting()
            self._asked = True
            row.invitations += 1

    def _engagement(self, visit: StopVisit, t: float) -> None:
        """The face samples stored since the stop's start, and the edge vote over them
        (:func:`frog_bt.maths.engagement.decide`, the executive's own rule)."""
        if not visit.face_stream or visit.start is None:
            return
        end = visit.a_end if visit.a_end is not None else t
        levels = [level for ts, level in self._samples if ts <= end]
        visit.samples = len(levels)
        if levels:
            d = decide(levels, self.plan.edge)
            visit.edge_engaged, visit.edge_total = d.engaged_votes, d.votes

    def _frontend_in(self, t: float, message: object) -> None:
        if isinstance(message, ContentDone) and message.part == "a":
            visit = self._stop_visit(message.poi)
            if visit is not None and visit.a_end is None:
                visit.a_end = t  # the engagement decision counts the samples up to here
        if isinstance(message, UserPositive | UserNegative) and self.current and self._asked:
            self._asked = False
            row = self.current
            if isinstance(message, UserPositive):
                row.accepted += 1
                self.said_yes += 1
                if row.approached:
                    row.visitors.append(row.approached[-1])
            else:
                row.declined += 1

    def _command(self, command: RobotCommand) -> None:
        # the drive back after an abort is the aborted tour's
        row = self.back if self.back is not None else self.current
        t, role, value = command.t, command.role, command.value
        if role == "goto" and isinstance(value, Pose):
            goal = self._target(command, value)
            self._approach = False
            if row is not None:
                row.goals += 1
                row.nav_retries += goal == self._failed
                row.t1 = t
            if row is self.current and self.current is not None:
                self._drive(t, goal)
            self._goal, self._failed = goal, None
        elif role == "approach" and isinstance(value, int):
            self._approach, self._goal = True, None
            row = self._touch(t)
            if row is not None:
                self._recruiting()
                row.approaches += 1
                row.approached.append(value)
        elif role == "dock" and isinstance(value, str):
            if row is not None and value == self._dock_failed:
                row.dock_retries += 1
            self._dock, self._dock_failed = value, None
        elif role == "icl":
            on = value == FaceStream.START
            if on and not self._stream_on:
                self._samples = []
            self._stream_on = on

    def _target(self, command: RobotCommand, pose: Pose) -> str:
        if command.goal is not None:
            return command.goal.target
        namer = self.plan.waypoint_of
        return namer(pose) if namer is not None else f"({pose.x:.1f}, {pose.y:.1f})"

    def _drive(self, t: float, waypoint: str) -> None:
        """A goal to ``waypoint``: a visit of its stop opens (a goal sent again to the same
        stop is the same visit); a goal elsewhere closes the visit open."""
        poi = self.plan.waypoints.get(waypoint)
        if poi not in self.plan.content:
            poi = None  # a stop without content (a waypoint of the route) is not counted
        visit = self._visit()
        if visit is not None and poi is not None and visit.poi == poi and not visit.arrived:
            return
        self._close_visit(moved_on=True)
        if poi is not None and self.current is not None:
            self.current.stops.append(StopVisit(poi, t, waypoint=waypoint))

    def _input(self, event: RobotInput) -> None:
        row = self.back if self.back is not None else self.current
        role, value, t = self._roles.get(event.topic), event.value, event.t
        if role == "pose" and isinstance(value, Pose):
            if self._pose is not None and row is not None:
                row.distance += step(self._pose, value)
            self._pose = (value.x, value.y)
        elif role == "response" and isinstance(value, int):
            self._response(Response.of(value), row)
        elif role == "docking_state" and isinstance(value, str):
            state = DockingState.of(value)
            if state in (DockingState.DOCKING, DockingState.UNDOCKING):
                self._dock = (
                    DockCommand.DOCK if state is DockingState.DOCKING else DockCommand.UNDOCK
                )
            elif state is DockingState.FAILED and self._dock is not None:
                self._dock_failed = self._dock
            elif state is DockingState.DOCKED and self.back is not None:
                self.back.t1, self.back = t, None  # home after the abort: the tour is over
        elif role == "faces" and self._stream_on and isinstance(value, FaceData):
            self._samples.extend(
                (t, face.engagement)
                for face in value.faces
                if face.distance <= self.plan.near and face.facing
            )
        elif role == "diagnostic" and row is not None and isinstance(value, Diagnostics):
            for status in value.statuses:
                if status.level == DiagnosticLevel.ERROR:
                    fault = (status.name, status.message)
                    if fault not in row.faults:
                        row.faults.append(fault)

    def _response(self, response: Response | None, row: TourRow | None) -> None:
        """A goal's or an approach's end (an active or unknown code changes nothing)."""
        if response is None or not response.terminal:
            return
        if self._approach:
            self._approach = False
            if row is not None:
                if response is SUCCEEDED:
                    row.approaches_ok += 1
                else:
                    row.approaches_rejected += 1
        elif self._goal is not None:
            visit = self._visit() if row is self.current else None
            mine = visit if visit is not None and visit.waypoint == self._goal else None
            if response is SUCCEEDED:
                if mine is not None:
                    mine.arrived = True
            else:
                self._failed = self._goal
                if row is not None:
                    row.failed_goals.append(self._goal)
                if mine is not None:
                    mine.goals_failed += 1
            self._answer = (mine, self._goal)
            self._goal = None

    def _doubted(self, event: Doubted) -> None:
        row = self.back or self.current
        if row is not None:
            row.doubted += 1
        answer, self._answer = self._answer, None
        if answer is None or answer[1] != event.goal:
            return
        # the latest answer was not acted on: the goal waits on for its next answer
        visit, self._goal = answer[0], event.goal
        if event.code == SUCCEEDED:
            if visit is not None and visit is self._visit() and visit.start is None:
                visit.arrived = False
        elif Response.of(event.code) is not None:
            if row is not None and row.failed_goals and row.failed_goals[-1] == event.goal:
                row.failed_goals.pop()
            if visit is not None and visit.goals_failed:
                visit.goals_failed -= 1
            self._failed = None

    def _operator(self, event: OperatorDone) -> None:
        row = self.back or self.current
        if row is None:
            return
        row.commands.append(StaffCommand(event.t, event.command, event.ok, event.by, event.text))
        if event.command == SKIP and event.ok:
            visit = self._visit()
            if visit is not None and not visit.played:
                visit.skipped = SkipWhy.OPERATOR


def step(before: tuple[float, float], pose: Pose) -> float:
    """Metres driven from ``before`` to ``pose`` (0 for a jump: a relocalisation)."""
    d = math.hypot(pose.x - before[0], pose.y - before[1])
    return d if 0.0 < d < JUMP else 0.0


def fold(plan: TourPlan, events: Iterable[Event]) -> TourLedger:
    """A ledger that has taken ``events``, in order."""
    ledger = TourLedger(plan)
    for event in events:
        ledger.feed(event)
    return ledger
