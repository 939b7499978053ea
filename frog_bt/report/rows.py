"""Tours from the pieces of many files, and one flat row per tour.

Pieces are taken in time order over the whole corpus. A piece that opens with the same
``tour started`` (the same seq: a resend that landed in the next file) continues the
tour before it; so does a piece that opens mid-tour (no ``tour started`` of its own)
when the tour before it had not ended:
a restarted executive resuming from its checkpoint (its front-end numbering starts
again at 1: the tour is marked ``resumed``), or a file rotated at the start of a tour.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, fields
from datetime import datetime
from typing import Any

from frog_bt.config import Site
from frog_bt.kernel.clock import SITE_TZ
from frog_bt.report.facts import FileFacts, Piece, StopFacts


@dataclass
class Tour:
    pieces: list[Piece]
    resumed: bool = False

    @property
    def first(self) -> Piece:
        return self.pieces[0]

    @property
    def last(self) -> Piece:
        return self.pieces[-1]


def join(files: list[FileFacts]) -> list[Tour]:
    """The tours of the corpus, in time order."""
    pieces = sorted((p for f in files for p in f.pieces), key=lambda p: (p.t0, p.file))
    # when an executive began numbering its front-end messages from 1 (it started; its
    # first file may hold no tour event: a resumed tour rotates into a file of its own)
    starts = sorted(t for f in files for t in f.new_executive)
    tours: list[Tour] = []
    for piece in pieces:
        prev = tours[-1] if tours else None
        if prev is not None and not prev.last.ended and piece.started_seq \
                and piece.started_seq == prev.first.started_seq:
            prev.pieces.append(piece)  # `tour started` resent after a file's rotation
            continue
        if piece.started is None:
            if prev is not None and not prev.last.ended:
                if any(prev.last.t1 < t <= piece.t0 for t in starts):
                    prev.resumed = True  # another executive took the tour over
                prev.pieces.append(piece)
                continue
            if not piece.stops:
                continue  # the end of a tour already ended (said again): nothing new
        tours.append(Tour([piece]))
    return tours


@dataclass
class Row:
    """One tour: the columns of the CSV and Parquet files (docs/REPORT.md)."""

    tour: int
    files: str  # the recordings it was read from, ';'-separated
    day: str  # local date, YYYY-MM-DD
    start: str  # local time of `tour started` (of its first event when resumed mid-way)
    hour: int
    duration_s: float
    distance_m: float
    stops_visited: str  # ";"-separated, in order, each once (a resumed stop starts again)
    stops_skipped: str  # 'POI2: navigation failed; ...'
    time_at_stops: str  # JSON {poi: seconds from part a to finish_poi}
    approaches: int
    approaches_accepted: int
    invitations: int  # ask_tour sent
    invitations_accepted: int
    invitations_declined: int
    introduction: str  # accepted | declined | no answer | none
    engagement: str  # JSON {poi: {samples, edge_engaged, edge_votes, decision}}
    parts: str  # 'POI1 ab; POI2 a; ...'
    variants: str  # waypoints played that are time-of-day variants, ';'-separated
    faults: str
    retries: int  # goals sent again to a waypoint already sent in this tour
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


def _poi(waypoint: str, pois: list[str]) -> str:
    return next((p for p in sorted(pois, key=len, reverse=True) if waypoint.startswith(p)),
                waypoint)


def row(number: int, tour: Tour, site: Site) -> Row:
    pieces = tour.pieces
    stops: list[StopFacts] = [s for p in pieces for s in p.stops]
    order = [s.poi for s in site.tour.stops if s.content]  # stops with content to play
    visited = [s.poi for s in stops]
    failed = {_poi(g, order) for p in pieces for g in p.failed_goals}
    skipped_by_operator = any(o.startswith("skip (ok)") for p in pieces for o in p.operator)
    ended = tour.last.ended or "cut"
    reach = len(order) if ended == "ended" else max(
        (order.index(v) + 1 for v in visited if v in order), default=0)
    skipped = []
    for poi in order[:reach]:
        if poi in visited:
            continue
        why = ("navigation failed" if poi in failed
               else "operator" if skipped_by_operator else "not visited")
        skipped.append(f"{poi}: {why}")
    start_t = tour.first.started if tour.first.started is not None else tour.first.t0
    local = datetime.fromtimestamp(start_t, SITE_TZ)
    goals = [g for p in pieces for g in p.goals]
    invitations = sum(p.invitations for p in pieces)
    accepted = sum(p.accepted for p in pieces)
    declined = sum(p.declined for p in pieces)
    introduction = ("none" if not invitations else "accepted" if accepted
                    else "declined" if declined else "no answer")
    variants = [s.waypoint for s in stops if s.waypoint != s.poi]
    engagement = {s.poi: {"samples": s.samples, "edge_engaged": s.edge_engaged,
                          "edge_votes": s.edge_total,
                          "decision": "b" if "b" in s.parts else "a only"}
                  for s in stops if s.face_stream}
    return Row(
        tour=number, files=";".join(dict.fromkeys(p.file.rsplit("/", 1)[-1] for p in pieces)),
        day=f"{local:%Y-%m-%d}", start=local.isoformat(timespec="seconds"), hour=local.hour,
        duration_s=round(tour.last.t1 - start_t, 1),
        distance_m=round(sum(p.distance for p in pieces), 1),
        stops_visited=";".join(dict.fromkeys(visited)), stops_skipped="; ".join(skipped),
        time_at_stops=json.dumps({s.poi: round(s.seconds, 1) for s in stops
                                  if s.seconds is not None}),
        approaches=sum(p.approaches for p in pieces),
        approaches_accepted=sum(p.approaches_ok for p in pieces),
        invitations=invitations, invitations_accepted=accepted,
        invitations_declined=declined, introduction=introduction,
        engagement=json.dumps(engagement),
        parts="; ".join(f"{s.poi} {s.parts}" for s in stops),
        variants=";".join(variants),
        faults="; ".join(dict.fromkeys(f for p in pieces for f in p.faults)),
        retries=len(goals) - len(set(goals)),
        operator="; ".join(o for p in pieces for o in p.operator),
        alerts="; ".join(a for p in pieces for a in p.alerts),
        ended=ended, reason=tour.last.reason, resumed=tour.resumed)


def rows(files: list[FileFacts], site: Site) -> list[Row]:
    return [row(i, t, site) for i, t in enumerate(join(files), 1)]
