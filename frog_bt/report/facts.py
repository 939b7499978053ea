"""What one recording tells, read from its channels without re-running the tree.

:func:`read_file` runs in a worker (a process, or a dask worker): it takes a path and the
site, reads the channels it needs in time order and returns a :class:`FileFacts`, plain
picklable data: the tour pieces found in the file (:class:`Piece`), or the reason the
file could not be read. A piece begins at ``tour started`` or, in a file that opens
mid-tour (a restarted executive resuming from its checkpoint, or a file rotated at the
start of a tour), at the first tour event; it ends at ``tour ended``/``aborted`` or at
the end of the file. :mod:`frog_bt.report.rows` joins the pieces into tours.

Channels read: ``/frontend/out`` (tour, start_poi, finish_poi, ask_tour),
``/frontend/in`` (user_positive/negative, content_done), ``/GotoWayPoint``,
``/ApproachPeopleFar``, ``/FROG_response``, ``/ICL_command``, ``/ICL_FaceDataStream``,
``/FROG_pose``, ``/diagnostic``, ``/frog_bt/operator``, ``/frog_bt/alert`` and
``/frog_bt/primer`` (a rotated file: the front-end seqs sent just before it, so that a
resend across the rotation is not taken for a new command).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frog_bt.config import Site
from frog_bt.maths.engagement import decide
from frog_bt.rosbridge.msgs import POSE
from frog_bt.tools.mcapfile import RecordingError, open_recording
from frog_bt.wire import SUCCEEDED

SUCCESS = SUCCEEDED  # /FROG_response: the goal or approach succeeded
ERROR_LEVEL = 2  # diagnostic_msgs/DiagnosticStatus ERROR
OWN = frozenset({"/frontend/in", "/frontend/out", "/frog_bt/operator", "/frog_bt/alert",
                 "/frog_bt/primer"})


@dataclass
class StopFacts:
    poi: str
    waypoint: str = ""  # the time-of-day variant played (POI1a / POI1b)
    parts: str = ""  # "a", "ab"
    start: float | None = None  # part a started
    end: float | None = None  # finish_poi
    samples: int = 0  # face samples stored (near and facing) from the stop to part a's end
    edge_engaged: int = 0
    edge_total: int = 0
    face_stream: bool = False
    a_end: float | None = None  # the front end said part a was done

    @property
    def seconds(self) -> float | None:
        return None if self.start is None or self.end is None else self.end - self.start


@dataclass
class Piece:
    """One tour, or the part of one that a file holds."""

    file: str
    first_seq: int  # the first new front-end seq of the executive in this file
    started: float | None = None  # `tour started` (None: the file opens mid-tour)
    started_seq: int = 0  # its front-end seq: a resend of it in the next file is no new tour
    t0: float = 0.0  # first event of the piece
    t1: float = 0.0  # last event of the piece
    ended: str = ""  # "ended" | "aborted" | "" (the file ended first)
    reason: str = ""
    distance: float = 0.0
    stops: list[StopFacts] = field(default_factory=list)
    goals: list[str] = field(default_factory=list)  # waypoint of each goal, in order
    failed_goals: list[str] = field(default_factory=list)  # goals answered 3/4
    approaches: int = 0
    approaches_ok: int = 0
    invitations: int = 0
    accepted: int = 0
    declined: int = 0
    faults: list[str] = field(default_factory=list)
    operator: list[str] = field(default_factory=list)  # "skip (ok)", "home (refused: ...)"
    alerts: list[str] = field(default_factory=list)  # kinds raised


@dataclass
class FileFacts:
    file: str
    pieces: list[Piece] = field(default_factory=list)
    error: str = ""  # unreadable: why (the file is reported and skipped)
    recovered: str = ""  # a file cut short: what was read of it
    start: float = 0.0  # first message, seconds
    new_executive: list[float] = field(default_factory=list)  # when one began numbering


class _Reader:
    """A state machine over one file's messages, in time order."""

    def __init__(self, path: str, site: Site) -> None:
        self.site = site
        self.path = path
        self.out: list[Piece] = []
        self.piece: Piece | None = None
        self.first_seq = 0
        self.pose: tuple[float, float] | None = None
        self.goal: str | None = None
        self.approach = False
        self.asked = False
        self.stream_on = False
        self.samples: list[tuple[float, float]] = []  # (t, level) while the stream is on
        self.seen: set[int] = set()  # front-end seqs sent (a resend has the same one)
        self.numbered_from_1: list[float] = []  # when a seq 1 went out: a new executive
        self.face_stops = {s.poi for s in site.tour.stops if s.face_stream}
        self.near = site.engagement.near
        self.edge = site.engagement.edge

    def _open(self, t: float, started: bool) -> Piece:
        if self.piece is None:
            self.piece = Piece(self.path, first_seq=self.first_seq,
                               started=t if started else None, t0=t, t1=t)
            self.out.append(self.piece)
        return self.piece

    def _tour_event(self, t: float) -> Piece:
        piece = self._open(t, started=False)
        piece.t1 = t
        return piece

    def _stop(self, poi: str) -> StopFacts | None:
        if self.piece is None:
            return None
        for stop in reversed(self.piece.stops):
            if stop.poi == poi:
                return stop
        return None

    def frontend_out(self, t: float, msg: dict[str, Any]) -> None:
        kind = msg.get("type")
        seq = msg.get("seq")
        if kind == "ack" or not isinstance(seq, int):
            return
        if seq == 1:
            self.seen.clear()  # a new executive numbers from 1 again
            self.numbered_from_1.append(t)
        elif seq in self.seen:
            return  # a resend (datagram loss): not a new command
        self.seen.add(seq)
        if not self.first_seq:
            self.first_seq = seq
        if kind == "tour":
            state = msg.get("state")
            if state == "started":
                if self.piece is not None and self.piece.started is None \
                        and not self.piece.stops:
                    self.piece.started = t  # a rotated file's opening events, then started
                elif self.piece is not None:
                    return  # said again (a resend taken anew): the same tour
                piece = self._open(t, started=True)
                piece.t1, piece.started_seq = t, seq
            elif state in ("ended", "aborted"):
                piece = self._tour_event(t)
                piece.ended, piece.reason = str(state), str(msg.get("reason") or "")
                self.piece = None
            return
        if kind == "start_poi":
            piece = self._tour_event(t)
            poi, part = str(msg.get("poi")), str(msg.get("part"))
            stop = self._stop(poi)
            if part == "a" or stop is None:
                stop = StopFacts(poi, str(msg.get("waypoint") or poi), face_stream=(
                    poi in self.face_stops))
                piece.stops.append(stop)
                stop.start = t
            if part not in stop.parts:
                stop.parts += part
            if part == "b":
                self._engagement(stop, t)
        elif kind == "finish_poi" and self.piece is not None:
            stop = self._stop(str(msg.get("poi")))
            if stop is not None:
                stop.end = t
                if "b" not in stop.parts:
                    self._engagement(stop, t)
            self.piece.t1 = t
        elif kind == "ask_tour" and self.piece is not None:
            self.asked = True
            self.piece.invitations += 1
            self.piece.t1 = t

    def _engagement(self, stop: StopFacts, t: float) -> None:
        """The face samples stored since the stop's start, and the edge vote over them."""
        if not stop.face_stream or stop.start is None:
            return
        end = stop.a_end if stop.a_end is not None else t
        levels = [level for ts, level in self.samples if ts <= end]  # since the stream began
        stop.samples = len(levels)
        if levels:
            d = decide(np.asarray(levels), self.edge)
            stop.edge_engaged, stop.edge_total = d.engaged_votes, d.votes

    def frontend_in(self, t: float, msg: dict[str, Any]) -> None:
        kind = msg.get("type")
        if kind == "content_done" and msg.get("part") == "a":
            stop = self._stop(str(msg.get("poi")))
            if stop is not None and stop.a_end is None:
                stop.a_end = t  # the decision counts the samples up to here
        if kind in ("user_positive", "user_negative") and self.piece is not None \
                and self.asked:
            self.asked = False
            if kind == "user_positive":
                self.piece.accepted += 1
            else:
                self.piece.declined += 1

    def ros(self, t: float, topic: str, msg: dict[str, Any]) -> None:
        site = self.site
        if topic == site.topic("pose"):
            p = msg.get("pose", {}).get("position", {})
            x, y = p.get("x"), p.get("y")
            if isinstance(x, int | float) and isinstance(y, int | float):
                if self.pose is not None and self.piece is not None:
                    step = math.hypot(x - self.pose[0], y - self.pose[1])
                    if step < 10.0:  # a jump is a relocalisation, not a drive
                        self.piece.distance += step
                self.pose = (x, y)
        elif topic == site.topic("goto"):
            self.goal, self.approach = _waypoint(site, msg), False
            if self.piece is not None:
                self.piece.goals.append(self.goal)
        elif topic == site.topic("approach"):
            self.approach = True
            if self.piece is not None:
                self.piece.approaches += 1
        elif topic == site.topic("response"):
            code = msg.get("data")
            if self.piece is None or code not in (2, 3, 4):
                return
            if self.approach:
                self.approach = False
                if code == SUCCESS:
                    self.piece.approaches_ok += 1
            elif self.goal is not None:
                if code != SUCCESS:
                    self.piece.failed_goals.append(self.goal)
                self.goal = None
        elif topic == site.topic("icl"):
            on = msg.get("data") == "start"
            if on and not self.stream_on:
                self.samples = []
            self.stream_on = on
        elif topic == site.topic("faces") and self.stream_on:
            for face in msg.get("faces") or ():
                try:
                    if float(face["distance"]) <= self.near and face["facing"] is True:
                        self.samples.append((t, float(face["engagement"])))
                except (KeyError, TypeError, ValueError):
                    continue
        elif topic == site.topic("diagnostic") and self.piece is not None:
            for status in msg.get("status") or ():
                if isinstance(status, dict) and status.get("level") == ERROR_LEVEL:
                    name = f"{status.get('name')}: {status.get('message')}"
                    if name not in self.piece.faults:
                        self.piece.faults.append(name)

    def own(self, t: float, topic: str, msg: dict[str, Any]) -> None:
        if topic == "/frog_bt/primer":  # a rotated file: the seqs sent just before it
            seqs = msg.get("frontend_out_seqs") or []
            self.seen.update(s for s in seqs if isinstance(s, int))
            return
        if self.piece is None:
            return
        if topic == "/frog_bt/operator":
            done = "ok" if msg.get("ok") else "refused"
            self.piece.operator.append(f"{msg.get('command')} ({done})")
        elif topic == "/frog_bt/alert" and msg.get("state") == "raised":
            self.piece.alerts.append(str(msg.get("kind")))


def _waypoint(site: Site, msg: dict[str, Any]) -> str:
    try:
        pose = POSE.convert(msg)
    except Exception:
        return "?"
    for name, poi in site.pois.items():
        if abs(poi.x - pose.x) < 1e-3 and abs(poi.y - pose.y) < 1e-3:
            return name
    return f"({pose.x:.1f}, {pose.y:.1f})"


def read_file(path: str, site: Site) -> FileFacts:
    """The tour pieces in one recording; any failure is an unreadable file, never a crash."""
    try:
        recording = open_recording(Path(path))
        if "/frontend/out" not in recording.types:
            return FileFacts(path, error="not a frog-bt tour recording (no /frontend/out)")
        reader = _Reader(path, site)
        ros_topics = {site.topic(r) for r in ("pose", "goto", "approach", "response", "icl",
                                              "faces", "diagnostic")}
        start = None
        for topic, ns, data in recording.messages():
            t = ns / 1e9
            if start is None:
                start = t
            if topic not in ros_topics and topic not in OWN:
                continue
            try:
                msg = json.loads(data)
            except ValueError:
                continue
            if not isinstance(msg, dict):
                continue
            if topic == "/frontend/out":
                reader.frontend_out(t, msg)
            elif topic == "/frontend/in":
                reader.frontend_in(t, msg)
            elif topic in ros_topics:
                reader.ros(t, topic, msg)
            else:
                reader.own(t, topic, msg)
        return FileFacts(path, reader.out, recovered=recording.recovered, start=start or 0.0,
                         new_executive=reader.numbered_from_1)
    except RecordingError as exc:
        return FileFacts(path, error=str(exc).replace(f"{path}: ", ""))
    except Exception as exc:  # a damaged file must not stop the corpus
        return FileFacts(path, error=f"{type(exc).__name__}: {exc}".splitlines()[0][:200])
