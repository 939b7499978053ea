"""Tours from the pieces of many files, and one flat row per tour.

Pieces are joined within one run (the files one executive wrote, those it rotated into
and those of an executive that resumed it: they share the run id,
:mod:`frog_bt.offline.report.runs`), so that two runs' tours, which may overlap in time,
are never taken for one; files recorded before run ids are joined within one directory
(one robot's ``--record DIR``). In time order:

* a piece that opens with its file (no ``tour started`` of its own) continues the tour
  before it when that tour has not ended: the tour file after a rotation, or the file
  of a restarted executive that resumed the tour from its checkpoint;
* a piece whose ``tour started`` has the seq of the open tour's, with no restart
  between, is a resend that landed in the next file: the same tour (one executive never
  uses a seq twice). So is, there, the end of the tour before, resent: seqs only grow,
  and an end whose seq is below the open tour's start is not its end.

A tour is ``resumed`` when an executive started (a file of its own began) between two
of its pieces. The stop a restart cut short and the resumed executive plays again is
one visit, its times added.
"""

from __future__ import annotations

import bisect
import enum
import itertools
from dataclasses import asdict, dataclass, field, fields, replace
from datetime import date, datetime
from pathlib import Path
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.config import Site
from frog_bt.engine.operator import Command
from frog_bt.model.tours import SkipWhy, StopVisit, skips
from frog_bt.offline.report.alerts import Episode, episodes, runs_of
from frog_bt.offline.report.causes import Cause, Incident
from frog_bt.offline.report.facts import FileFacts, OperatorCall, Piece
from frog_bt.offline.report.runs import lanes

NAV_FAILED = SkipWhy.NAVIGATION.value
OPERATOR_SKIP = SkipWhy.OPERATOR.value
NOT_RECORDED = SkipWhy.NOT_RECORDED.value


class Intervention(enum.StrEnum):
    """A person had to act (docs/REPORT.md, field reliability)."""

    HELP = "help answered"  # retry, done_by_hand: the robot held and asked
    HOME = "home"
    SKIP = "skip"
    ACK = "alert acknowledged"


INTERVENING = {
    Command.RETRY: Intervention.HELP,
    Command.DONE_BY_HAND: Intervention.HELP,
    Command.HOME: Intervention.HOME,
    Command.SKIP: Intervention.SKIP,
    Command.ACK_ALERT: Intervention.ACK,
}


@dataclass
class Tour:
    robot: str  # the directory its recordings are in
    pieces: list[Piece]
    restarts: list[float] = field(default_factory=list)  # of its lane, in order
    lane: str = ""  # the files it was joined from: a run's, or a directory's (lane_of)

    @property
    def first(self) -> Piece:
        return self.pieces[0]

    @property
    def last(self) -> Piece:
        return self.pieces[-1]

    def restarted(self, after: float, until: float) -> bool:
        """An executive of this robot started in (after, until]."""
        i = bisect.bisect_right(self.restarts, after)
        return i < len(self.restarts) and self.restarts[i] <= until

    @property
    def start(self) -> float:
        """``tour started``, or the first event read when that is not in the corpus."""
        return self.first.started if self.first.started is not None else self.first.t0

    @property
    def resumed(self) -> bool:
        """An executive started between the end of one of its pieces and the last event
        of the next: a new executive carried the tour on."""
        return any(self.restarted(p.t1, q.t1) for p, q in itertools.pairwise(self.pieces))


def join(files: list[FileFacts]) -> list[Tour]:
    """The tours of the corpus, in order of their first event."""
    tours = [t for lane, group in lanes(files).items() for t in _join(lane, group)]
    return sorted(tours, key=lambda t: (t.first.t0, t.robot, t.lane))


def _join(lane: str, files: list[FileFacts]) -> list[Tour]:
    robot = str(Path(files[0].file).parent)
    restarts = sorted(r for f in files for r in f.restarts)
    pieces = sorted((p for f in files for p in f.pieces), key=lambda p: (p.t0, p.file))
    tours: list[Tour] = []
    for piece in pieces:
        prev = tours[-1] if tours else None
        open_ = prev is not None and not prev.last.ended
        if piece.started is not None:
            if (
                open_
                and prev is not None
                and piece.started_seq == prev.first.started_seq
                and prev.first.started is not None
                and not prev.restarted(prev.first.started, piece.started)
            ):
                prev.pieces.append(piece)  # `tour started` resent after a file's rotation
            else:
                tours.append(Tour(robot, [piece], restarts, lane))
        elif open_ and prev is not None:
            if (
                piece.ended
                and prev.first.started is not None
                and piece.end_seq < prev.first.started_seq
                and not prev.restarted(prev.first.started, piece.t1)
            ):
                # seqs only grow: the end of the tour before, resent into the tour file
                piece = replace(piece, ended="", reason="", end_seq=0)
            prev.pieces.append(piece)  # rotated, or carried on by a restarted executive
        elif piece.stops or piece.invitations:
            tours.append(Tour(robot, [piece], restarts, lane))  # its start is not in the corpus
        # else: the tail of a tour whose start is not in the corpus, with nothing in it
    return tours


@dataclass(frozen=True)
class Skip:
    poi: str
    why: str  # a SkipWhy: operator | navigation failed | visitor lost | not recorded | not visited

    def __str__(self) -> str:
        return f"{self.poi}: {self.why}"


@dataclass(frozen=True)
class StopTime:
    poi: str
    seconds: float  # from part a to finish_poi, the visits of the stop added

    def __str__(self) -> str:
        return f"{self.poi} {self.seconds:g} s"


@dataclass(frozen=True)
class Played:
    poi: str
    parts: str  # "a", "ab"

    def __str__(self) -> str:
        return f"{self.poi} {self.parts}"


@dataclass(frozen=True)
class Visit:
    """One visit of a face-stream stop: what the engagement gate saw and did."""

    poi: str
    waypoint: str  # the time-of-day variant played
    samples: int  # face samples stored (near and facing) to the end of part a
    edge_engaged: int
    edge_votes: int
    decision: str  # b | a only | none

    def __str__(self) -> str:
        return f"{self.poi} {self.decision} ({self.edge_engaged}/{self.edge_votes})"


@dataclass(frozen=True)
class Call:
    """An operator command during the tour, with its answer."""

    at_s: float  # seconds from the tour's start
    command: str
    ok: bool
    by: str  # console, ctl, link ("" when not recorded)
    text: str

    def __str__(self) -> str:
        return f"{self.command} ({'ok' if self.ok else 'refused'})"


@dataclass(frozen=True)
class AlertRow:
    """An alert raised during the tour: its acknowledgement and resolution."""

    id: str
    kind: str
    severity: str
    raised_s: float  # seconds from the tour's start
    acknowledged_s: float | None  # seconds from the raise (None: never)
    acknowledged_by: str
    cleared_s: float | None  # seconds from the raise (None: not in the recordings)
    repeats: int  # told again unacknowledged

    def __str__(self) -> str:
        ack = "" if self.acknowledged_s is None else f", ack {self.acknowledged_s:g} s"
        return f"{self.kind}{ack}"


@dataclass
class Row:
    """One tour: the columns of the CSV, Parquet and JSON outputs (docs/REPORT.md).
    Lists stay lists (Parquet list columns, JSON arrays); CSV shows them as text."""

    tour: int
    robot: str  # the directory of its recordings
    files: list[str]  # the recordings it was read from
    day: date  # local date
    start: datetime  # local time of `tour started` (of its first event when not recorded)
    hour: int
    duration_s: float
    distance_m: float
    stops_reached: list[str]  # arrived, not skipped; in order (a stop visited again: again)
    stops_played: list[str]  # reached, and its part a played to its end
    stops_skipped: list[Skip]  # content stops not reached, each once, and why
    time_at_stops: list[StopTime]
    approaches: int
    approaches_accepted: int
    approaches_rejected: int
    visitors: int  # people approached who said yes
    visitors_lost: int  # visitors who stopped following: another was recruited
    invitations: int  # ask_tour sent
    invitations_accepted: int
    invitations_declined: int
    introduction: str  # accepted | declined | no answer | none
    engagement: list[Visit]
    parts: list[Played]
    variants: list[str]  # waypoints played that are time-of-day variants
    faults: list[str]  # 'name: message'
    nav_retries: int  # goals sent again to the waypoint whose goal had just failed
    dock_retries: int  # dock/undock sent again after the docking failed
    restarts: int  # executives started during the tour (it was resumed)
    operator: list[Call]
    alerts: list[AlertRow]
    interventions: int  # a person acted: help answered, home, skip, alert acknowledged
    incidents: list[Incident]
    ended: str  # ended | aborted | cut (the recordings stop first)
    reason: str
    resumed: bool

    @classmethod
    def columns(cls) -> list[str]:
        return [f.name for f in fields(cls)]

    def as_dict(self) -> dict[str, Any]:
        """Python values (dates, times, lists of dicts): for Parquet."""
        return asdict(self)

    def as_json(self) -> dict[str, Any]:
        """JSON values: the date and time as ISO 8601 text (the time with its offset)."""
        return {
            **self.as_dict(),
            "day": self.day.isoformat(),
            "start": self.start.isoformat(timespec="seconds"),
        }

    def as_text(self) -> dict[str, str]:
        """One plain column per figure, for CSV: lists shown joined with '; '."""
        out: dict[str, str] = {}
        for name, value in self.as_json().items():
            if name in ("start", "day"):
                out[name] = value
            elif isinstance(value, list):
                out[name] = "; ".join(str(v) for v in getattr(self, name))
            else:
                out[name] = str(value)
        return out


def visits(tour: Tour) -> list[StopVisit]:
    """The tour's stop visits in order; a visit cut by a restart and carried on by the
    resumed executive is one (copies: the pieces are left as they are)."""
    out: list[StopVisit] = []
    last: Piece | None = None  # the piece of out[-1]
    for piece in tour.pieces:
        for stop in piece.stops:
            cut = out[-1] if out else None
            if (
                cut is not None
                and last is not piece
                and cut.poi == stop.poi
                and tour.restarted(cut.t, stop.t)
            ):
                out[-1] = cut.carried_on(stop)
            else:
                out.append(replace(stop))
            last = piece
    return out


def skipped(tour: Tour, site: Site, stops: list[StopVisit], ended: str) -> list[Skip]:
    """'POI: why' for each content stop of the tour order the tour did not reach
    (:func:`frog_bt.model.tours.skips`): for a tour that did not end, only up to the last
    stop it reached or skipped; ``not recorded (restart)`` for one between what the
    recordings before and after a restart hold (a killed writer loses its last second)."""
    order = [s.poi for s in site.tour.stops if s.content]
    lost: set[str] = set()  # stops in a gap the recordings of a restart leave
    at = {poi: i for i, poi in enumerate(order)}
    pieces = tour.pieces
    for k in range(1, len(pieces)):
        if tour.restarted(pieces[k - 1].t1, pieces[k].t1):
            before = [at[s.poi] for p in pieces[:k] for s in p.stops if s.poi in at]
            after = [at[s.poi] for p in pieces[k:] for s in p.stops if s.poi in at]
            lost.update(order[max(before, default=-1) + 1 : min(after, default=len(order))])
    return [Skip(poi, why.value) for poi, why in skips(stops, order, ended, frozenset(lost))]


def row(
    number: int, tour: Tour, site: Site, calls: list[OperatorCall], alerts: list[Episode]
) -> Row:
    """The row of one tour; ``calls`` and ``alerts``: those of its time span."""
    pieces = tour.pieces
    stops = visits(tour)
    ended = tour.last.ended or "cut"
    start_t = tour.start
    local = datetime.fromtimestamp(start_t, SITE_TZ)
    invitations = sum(p.invitations for p in pieces)
    accepted = sum(p.accepted for p in pieces)
    declined = sum(p.declined for p in pieces)
    introduction = (
        "none"
        if not invitations
        else "accepted"
        if accepted
        else "declined"
        if declined
        else "no answer"
    )
    seconds: dict[str, float] = {}
    for s in stops:
        if s.seconds is not None:
            seconds[s.poi] = round(seconds.get(s.poi, 0.0) + s.seconds, 1)
    skipped_stops = skipped(tour, site, stops, ended)
    visitors = len({v for p in pieces for v in p.visitors})
    faults = list(dict.fromkeys(f for p in pieces for f in p.faults))
    ops = [Call(round(c.t - start_t, 1), c.command, c.ok, c.by, c.text) for c in calls]
    restarts = sum(tour.restarted(p.t1, q.t1) for p, q in itertools.pairwise(pieces))
    base = Row(
        tour=number,
        robot=Path(tour.robot).name,
        files=list(dict.fromkeys(Path(p.file).name for p in pieces)),
        day=local.date(),
        start=local.replace(microsecond=0),
        hour=local.hour,
        duration_s=round(tour.last.t1 - start_t, 1),
        distance_m=round(sum(p.distance for p in pieces), 1),
        stops_reached=[s.poi for s in stops if s.reached],
        stops_played=[s.poi for s in stops if s.played],
        stops_skipped=skipped_stops,
        time_at_stops=[StopTime(poi, t) for poi, t in seconds.items()],
        approaches=sum(p.approaches for p in pieces),
        approaches_accepted=sum(p.approaches_ok for p in pieces),
        approaches_rejected=sum(p.approaches_rejected for p in pieces),
        visitors=visitors,
        visitors_lost=max(0, visitors - 1),
        invitations=invitations,
        invitations_accepted=accepted,
        invitations_declined=declined,
        introduction=introduction,
        engagement=[
            Visit(s.poi, s.waypoint, s.samples, s.edge_engaged, s.edge_total, s.decision)
            for s in stops
            if s.face_stream and s.parts
        ],
        parts=[Played(s.poi, s.parts) for s in stops if s.parts],
        variants=list(dict.fromkeys(s.waypoint for s in stops if s.parts and s.waypoint != s.poi)),
        faults=[f"{name}: {message}" for name, message in faults],
        nav_retries=sum(p.nav_retries for p in pieces),
        dock_retries=sum(p.dock_retries for p in pieces),
        restarts=restarts,
        operator=ops,
        alerts=[
            AlertRow(
                e.id,
                e.kind,
                e.severity,
                round(e.raised - start_t, 1),
                None if e.to_acknowledge is None else round(e.to_acknowledge, 1),
                e.acknowledged_by,
                None if e.cleared is None else round(e.cleared - e.raised, 1),
                e.repeats,
            )
            for e in alerts
        ],
        interventions=sum(intervention(c) is not None for c in calls),
        incidents=[],
        ended=ended,
        reason=tour.last.reason,
        resumed=tour.resumed,
    )
    base.incidents = incidents(base, [name for name, _ in faults], calls, alerts)
    return base


def intervention(call: OperatorCall) -> Intervention | None:
    """What a person did with an accepted command, when it is an intervention."""
    if not call.ok or call.command not in INTERVENING:
        return None
    return INTERVENING[Command(call.command)]


def incidents(
    r: Row, fault_names: list[str], calls: list[OperatorCall], alerts: list[Episode]
) -> list[Incident]:
    """The tour's incidents, each event once (:mod:`frog_bt.offline.report.causes`)."""
    out = [Incident(Cause.NAV_RETRY)] * r.nav_retries
    out += [Incident(Cause.STOP_GIVEN_UP, s.poi) for s in r.stops_skipped if s.why == NAV_FAILED]
    out += [Incident(Cause.APPROACH_REJECTED)] * r.approaches_rejected
    out += [Incident(Cause.INVITATION_DECLINED)] * r.invitations_declined
    out += [Incident(Cause.VISITOR_LOST)] * r.visitors_lost
    out += [Incident(Cause.DOCK_RETRY)] * r.dock_retries
    out += [Incident(Cause.FAULT, name) for name in dict.fromkeys(fault_names)]
    for e in alerts:
        if e.help:
            out.append(Incident(Cause.HELP_NEEDED, e.kind))
        elif not (e.kind == "fault" and fault_names) and e.kind != "stop_given_up":
            out.append(Incident(Cause.ALERT, e.kind))  # (those two are counted above)
    told = [c.command for c in calls if c.ok and c.command in (Command.HOME, Command.SKIP)]
    out += [Incident(Cause.OPERATOR, command) for command in told]
    out += [Incident(Cause.RESTART)] * r.restarts
    if r.ended == "aborted" and not fault_names and Command.HOME not in told:
        out.append(Incident(Cause.ABORTED, r.reason or "?"))
    elif r.ended == "cut":
        out.append(Incident(Cause.CUT))
    return out


def rows(files: list[FileFacts], site: Site) -> list[Row]:
    """One row per tour of the corpus, numbered from 1 in order of their start."""
    out = []
    tours = join(files)
    spans: dict[str, list[tuple[float, float, int]]] = {}
    for i, t in enumerate(tours):
        spans.setdefault(t.lane, []).append((t.start, t.last.t1, i))
    calls: dict[int, list[OperatorCall]] = {}
    alerts: dict[int, list[Episode]] = {}
    for lane, group in lanes(files).items():
        own = spans.get(lane, [])
        robot_calls = [c for f in group for c in f.operator]
        for c in sorted(robot_calls, key=lambda c: c.t):
            k = _during(own, c.t)
            if k is not None:
                calls.setdefault(k, []).append(c)
        for e in episodes(
            [a for f in group for a in f.alerts],
            robot_calls,
            runs_of(group),
        ):
            k = _during(own, e.raised)
            if k is not None:
                alerts.setdefault(k, []).append(e)
    for i, t in enumerate(tours):
        out.append(row(i + 1, t, site, calls.get(i, []), alerts.get(i, [])))
    return out


def by_robot(files: list[FileFacts]) -> dict[str, list[FileFacts]]:
    """The files of each robot (its directory: field reliability's robot-days)."""
    robots: dict[str, list[FileFacts]] = {}
    for f in files:
        robots.setdefault(str(Path(f.file).parent), []).append(f)
    return robots


def _during(spans: list[tuple[float, float, int]], t: float) -> int | None:
    """The tour whose span holds ``t`` (the latest to start, when two overlap)."""
    for start, end, i in reversed(spans):
        if start <= t <= end:
            return i
    return None
