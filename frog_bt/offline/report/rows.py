"""Tours from the pieces of many files, and one flat row per tour.

Pieces are joined within one directory (one robot's ``--record DIR``; a fleet's
recordings go in one directory per robot, so that two robots' tours, which overlap in
time, are never taken for one), in time order:

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
import itertools
import json
from dataclasses import asdict, dataclass, field, fields, replace
from datetime import datetime
from pathlib import Path
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.config import Site
from frog_bt.offline.report.facts import FileFacts, Piece, StopFacts, stop_of


@dataclass
class Tour:
    robot: str  # the directory its recordings are in
    pieces: list[Piece]
    restarts: list[float] = field(default_factory=list)  # of its robot, in order

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
    def resumed(self) -> bool:
        """An executive started between the end of one of its pieces and the last event
        of the next: a new executive carried the tour on."""
        return any(self.restarted(p.t1, q.t1) for p, q in itertools.pairwise(self.pieces))


def join(files: list[FileFacts]) -> list[Tour]:
    """The tours of the corpus, in order of their first event."""
    robots: dict[str, list[FileFacts]] = {}
    for f in files:
        robots.setdefault(str(Path(f.file).parent), []).append(f)
    tours = [t for robot, group in robots.items() for t in _join(robot, group)]
    return sorted(tours, key=lambda t: (t.first.t0, t.robot))


def _join(robot: str, files: list[FileFacts]) -> list[Tour]:
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
                tours.append(Tour(robot, [piece], restarts))
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
            tours.append(Tour(robot, [piece], restarts))  # its beginning is not in the corpus
        # else: the tail of a tour whose start is not in the corpus, with nothing in it
    return tours


@dataclass
class Row:
    """One tour: the columns of the CSV and Parquet files (docs/REPORT.md)."""

    tour: int
    robot: str  # the directory of its recordings
    files: str  # the recordings it was read from, ';'-separated
    day: str  # local date, YYYY-MM-DD
    start: str  # local time of `tour started` (of its first event when not recorded)
    hour: int
    duration_s: float
    distance_m: float
    stops_visited: str  # ';'-separated, in order (a stop visited again is listed again)
    stops_skipped: str  # 'POI2: navigation failed; POI3: operator'
    time_at_stops: str  # JSON {poi: seconds from part a to finish_poi, visits added}
    approaches: int
    approaches_accepted: int
    visitors: int  # people approached who said yes
    invitations: int  # ask_tour sent
    invitations_accepted: int
    invitations_declined: int
    introduction: str  # accepted | declined | no answer | none
    engagement: str  # JSON [{poi, samples, edge_engaged, edge_votes, decision}] per visit
    parts: str  # 'POI1 ab; POI2 a; ...'
    variants: str  # waypoints played that are time-of-day variants, ';'-separated
    faults: str
    nav_retries: int  # goals sent again to the waypoint whose goal had just failed
    dock_retries: int  # dock/undock sent again after the docking failed
    operator: str
    alerts: str
    ended: str  # ended | aborted | cut (the recordings stop first)
    reason: str
    resumed: bool

    @classmethod
    def columns(cls) -> list[str]:
        return [f.name for f in fields(cls)]

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def visits(tour: Tour) -> list[StopFacts]:
    """The tour's stop visits in order; a visit cut by a restart and played again by the
    resumed executive is one (copies: the pieces are left as they are)."""
    out: list[StopFacts] = []
    last: Piece | None = None  # the piece of out[-1]
    for piece in tour.pieces:
        for stop in piece.stops:
            cut = out[-1] if out else None
            if (
                cut is not None
                and last is not piece
                and cut.poi == stop.poi
                and cut.start is not None
                and stop.start is not None
                and tour.restarted(cut.start, stop.start)
            ):
                out[-1] = replace(
                    stop,
                    parts="".join(dict.fromkeys(cut.parts + stop.parts)),
                    before_restart=cut.seconds or 0.0,
                )
            else:
                out.append(replace(stop))
            last = piece
    return out


def skipped(tour: Tour, site: Site, stops: list[StopFacts], ended: str) -> list[str]:
    """'POI: why' for each content stop of the tour order not visited, or left by the
    operator; for a tour that did not end, only up to the last stop it reached. Why:
    ``navigation failed`` (a goal there answered 3/4), ``operator`` (a skip accepted there
    or on the way), ``not recorded (restart)`` (between what the recordings before and
    after a restart hold: a killed writer loses its last second) or ``not visited``."""
    order = [s.poi for s in site.tour.stops if s.content]
    names = stop_of(site)
    failed = {names.get(g, g) for p in tour.pieces for g in p.failed_goals}
    by_operator = {s for p in tour.pieces for s in p.operator_skips}
    visited = {s.poi for s in stops}
    reached = visited | failed | by_operator
    lost: set[str] = set()  # stops in a gap the recordings of a restart leave
    at = {poi: i for i, poi in enumerate(order)}
    pieces = tour.pieces
    for k in range(1, len(pieces)):
        if tour.restarted(pieces[k - 1].t1, pieces[k].t1):
            before = [at[s.poi] for p in pieces[:k] for s in p.stops if s.poi in at]
            after = [at[s.poi] for p in pieces[k:] for s in p.stops if s.poi in at]
            lost.update(order[max(before, default=-1) + 1 : min(after, default=len(order))])
    reach = (
        len(order)
        if ended == "ended"
        else max((order.index(poi) + 1 for poi in reached if poi in order), default=0)
    )
    out = []
    for poi in order[:reach]:
        if poi in by_operator:
            out.append(f"{poi}: operator")
        elif poi not in visited:
            why = (
                "navigation failed"
                if poi in failed
                else "not recorded (restart)"
                if poi in lost
                else "not visited"
            )
            out.append(f"{poi}: {why}")
    return out


def row(number: int, tour: Tour, site: Site) -> Row:
    pieces = tour.pieces
    stops = visits(tour)
    ended = tour.last.ended or "cut"
    start_t = tour.first.started if tour.first.started is not None else tour.first.t0
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
    engagement = [
        {
            "poi": s.poi,
            "samples": s.samples,
            "edge_engaged": s.edge_engaged,
            "edge_votes": s.edge_total,
            "decision": s.decision,
        }
        for s in stops
        if s.face_stream
    ]
    return Row(
        tour=number,
        robot=Path(tour.robot).name,
        files=";".join(dict.fromkeys(Path(p.file).name for p in pieces)),
        day=f"{local:%Y-%m-%d}",
        start=local.isoformat(timespec="seconds"),
        hour=local.hour,
        duration_s=round(tour.last.t1 - start_t, 1),
        distance_m=round(sum(p.distance for p in pieces), 1),
        stops_visited=";".join(s.poi for s in stops),
        stops_skipped="; ".join(skipped(tour, site, stops, ended)),
        time_at_stops=json.dumps(seconds),
        approaches=sum(p.approaches for p in pieces),
        approaches_accepted=sum(p.approaches_ok for p in pieces),
        visitors=len({v for p in pieces for v in p.visitors}),
        invitations=invitations,
        invitations_accepted=accepted,
        invitations_declined=declined,
        introduction=introduction,
        engagement=json.dumps(engagement),
        parts="; ".join(f"{s.poi} {s.parts}" for s in stops),
        variants=";".join(dict.fromkeys(s.waypoint for s in stops if s.waypoint != s.poi)),
        faults="; ".join(dict.fromkeys(f for p in pieces for f in p.faults)),
        nav_retries=sum(p.nav_retries for p in pieces),
        dock_retries=sum(p.dock_retries for p in pieces),
        operator="; ".join(o for p in pieces for o in p.operator),
        alerts="; ".join(a for p in pieces for a in p.alerts),
        ended=ended,
        reason=tour.last.reason,
        resumed=tour.resumed,
    )


def rows(files: list[FileFacts], site: Site) -> list[Row]:
    """One row per tour of the corpus, numbered from 1 in order of their start."""
    return [row(i, t, site) for i, t in enumerate(join(files), 1)]
