"""What one recording tells, read from its channels without re-running the tree.

:func:`read_file` runs in a worker (a process, or a dask worker): it takes a path and the
site, reads the channels it needs in time order and returns a :class:`FileFacts`, plain
picklable data: the tour pieces found in the file (:class:`Piece`), the times an
executive started in it, or the reason the file could not be read. An executive
starts a file of its own (``--record DIR``: an idle file without a primer, the files it
rotates into having one, or a tour's ``lead_in``; a file without frog-bt's metadata is
one whole run).
:mod:`frog_bt.offline.report.rows` joins the pieces into tours.

A piece begins at ``tour started``, or at the file's first message: a file may open
inside a tour (``--record DIR`` rotates at the start of a tour, so the tour file opens
just after its ``tour started``; a restarted executive carries on a tour from its
checkpoint in a new file, without a new ``tour started``). Such an opening piece keeps
everything up to the file's first ``tour started`` and is kept only when it holds
something of a tour (content, an invitation, an approach, a goal, a tour's end): the
opening of an idle file is no tour. A piece ends at ``tour ended`` (the robot is
docked by then), or after ``tour aborted`` once the robot has driven back and docked
(that drive is the tour's too), or at the end of the file.

Channels read, through the one decoder of recordings (:mod:`frog_bt.recordings.reader`),
as the executive's events it gives back: ``/frontend/out`` (tour, start_poi, finish_poi,
ask_tour: its new commands, and the seq of each), ``/frontend/in`` (user_positive/negative,
content_done), ``/GotoWayPoint``, ``/ApproachPeopleFar``,
``/FROG_response``, ``/docking/dock``, ``/docking/state``, ``/ICL_command``,
``/ICL_FaceDataStream``, ``/FROG_pose``, ``/diagnostic``, ``/frog_bt/operator``,
``/frog_bt/alert`` and ``/frog_bt/primer`` (a rotated file: the reader takes the
front-end seqs sent just before it, so that a resend across the rotation is not taken for
a new command). Topic
names are the site's. A message that does not decode is counted (:attr:`FileFacts.bad`)
and read past.
"""

from __future__ import annotations

import contextlib
import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from frog_bt.config import Site
from frog_bt.engine.operator import Command as OperatorCommand
from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import decode_datagram
from frog_bt.maths.engagement import decide
from frog_bt.model.channels import (
    ALERT,
    FRONTEND_IN,
    FRONTEND_OUT,
    OPERATOR,
    PRIMER,
    SITE_METADATA,
    TREE,
    Tree,
    from_ns,
)
from frog_bt.model.events import (
    AlertChanged,
    Datagram,
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
    FrontendMessage,
    StartPoi,
    Tour,
    UserNegative,
    UserPositive,
)
from frog_bt.model.outcomes import DiagnosticLevel, DockCommand, DockingState, FaceStream, TourState
from frog_bt.model.ros import Diagnostics, FaceData, Pose
from frog_bt.model.run import read_metadata
from frog_bt.model.wire import SUCCEEDED, Response
from frog_bt.recordings.mcapfile import RecordingError, open_recording
from frog_bt.recordings.reader import Item, Primed, Reader

JUMP = 10.0  # metres: a pose step this long is a relocalisation, not a drive
OWN = (FRONTEND_IN, FRONTEND_OUT, OPERATOR, ALERT, PRIMER, TREE)
HOUR = 3600.0  # distance is summed per clock hour (cheap), then per local day
ROS_ROLES = (
    "pose",
    "goto",
    "approach",
    "response",
    "dock",
    "docking_state",
    "icl",
    "faces",
    "diagnostic",
)
BAD_NOTED = 3  # reasons of bad messages a file's facts keep (all are counted)


@dataclass
class StopFacts:
    """One visit of a content stop: from its part a to its ``finish_poi``."""

    poi: str  # the logical POI (POI1)
    waypoint: str = ""  # the time-of-day variant played (POI1a / POI1b)
    parts: str = ""  # "a", "ab"
    start: float | None = None  # part a started
    end: float | None = None  # finish_poi
    samples: int = 0  # face samples stored (near and facing) from the stop to part a's end
    edge_engaged: int = 0
    edge_total: int = 0
    face_stream: bool = False
    a_end: float | None = None  # the front end said part a was done
    before_restart: float = 0.0  # seconds of this visit before a restart cut it (joined)

    @property
    def seconds(self) -> float | None:
        """Time at the stop: part a to ``finish_poi`` (and the time before a restart)."""
        if self.start is None or self.end is None:
            return None
        return self.end - self.start + self.before_restart

    @property
    def decision(self) -> str:
        """What the engagement gate did: ``b`` (part b played), ``a only`` (part a played
        to its end, no part b) or ``none`` (part a was cut before the gate)."""
        if "b" in self.parts:
            return "b"
        return "a only" if self.a_end is not None else "none"


@dataclass
class Piece:
    """One tour, or the part of one that a file holds."""

    file: str
    started: float | None = None  # `tour started` (None: the piece opens with the file)
    started_seq: int = 0  # its front-end seq: a resend of it in the next file is no new tour
    t0: float = 0.0  # first event of the piece
    t1: float = 0.0  # last event of the piece
    ended: str = ""  # "ended" | "aborted" | "" (the file ended first)
    reason: str = ""
    end_seq: int = 0  # the front-end seq of its `tour ended`/`aborted`
    distance: float = 0.0
    stops: list[StopFacts] = field(default_factory=list)
    goals: int = 0  # /GotoWayPoint sent
    failed_goals: list[str] = field(default_factory=list)  # waypoints of goals answered 3/4
    nav_retries: int = 0  # goals sent again to the waypoint whose goal had just failed
    dock_retries: int = 0  # dock/undock sent again after /docking/state failed
    approaches: int = 0
    approaches_ok: int = 0
    approached: list[int] = field(default_factory=list)  # person ids, in order
    visitors: list[int] = field(default_factory=list)  # the approached who said yes
    invitations: int = 0
    accepted: int = 0
    declined: int = 0
    approaches_rejected: int = 0  # approaches answered 3/4
    faults: list[tuple[str, str]] = field(default_factory=list)  # (name, message), each once
    operator_skips: list[str] = field(default_factory=list)  # stops the operator skipped

    def of_a_tour(self) -> bool:
        """Something only a tour does happened in it."""
        return bool(self.stops or self.invitations or self.approaches or self.goals or self.ended)


@dataclass(frozen=True)
class OperatorCall:
    """An operator command and its answer, as ``/frog_bt/operator`` recorded it."""

    t: float
    command: str
    ok: bool
    text: str
    id: str = ""  # ack_alert: the alert
    by: str = ""  # console, ctl, link ("" when not recorded)


@dataclass(frozen=True)
class AlertChange:
    """One change of an alert, as ``/frog_bt/alert`` recorded it."""

    t: float
    id: str
    kind: str
    state: str  # raised | cleared | acknowledged
    severity: str = "WARN"
    repeat: int = 0  # an escalation (the alert told again), not a new alert
    subject: str = ""


@dataclass
class FileFacts:
    file: str
    pieces: list[Piece] = field(default_factory=list)
    restarts: list[float] = field(default_factory=list)  # an executive started here
    end: float = 0.0  # last message, seconds
    operator: list[OperatorCall] = field(default_factory=list)  # all, in or out of tours
    alerts: list[AlertChange] = field(default_factory=list)  # all, in or out of tours
    metres: dict[int, float] = field(default_factory=dict)  # clock hour -> metres driven
    library: str = ""  # what wrote it (frog-bt and its version)
    tree: str = ""  # sha256 (12 hex) of the tree that ran, from /frog_bt/tree
    config: str = ""  # sha256 (12 hex) of the site configuration, from its metadata
    run: str = ""  # the run's UUID, from its metadata ("": recorded before run ids)
    robot_name: str = ""  # the robot's configured name, from the same metadata
    error: str = ""  # unreadable: why (the file is reported and skipped)
    recovered: str = ""  # a file cut short: what was read of it
    start: float = 0.0  # first message, seconds
    bad: int = 0  # messages that did not decode (counted, read past)
    bad_first: list[str] = field(default_factory=list)  # the first few: where and why


def stop_of(site: Site) -> dict[str, str]:
    """Waypoint (a POI or one of its time-of-day variants) -> logical POI of the tour."""
    out = {}
    for stop in site.tour.stops:
        out[stop.poi] = stop.poi
        for variant in site.variants.get(stop.poi, ()):
            out[variant.waypoint] = stop.poi
    return out


class _Pieces:
    """A state machine over one file's items, in time order (:meth:`take` each)."""

    def __init__(self, path: str, site: Site, roles: dict[str, str] | None = None) -> None:
        self.site = site
        self.path = path
        self.out: list[Piece] = []
        self.piece: Piece | None = None
        self.back: Piece | None = None  # an aborted tour's piece until the robot docks
        self.opening = True  # the piece open is the file's opening one (no `tour started`)
        self.primed = False  # the file opens with a /frog_bt/primer (an idle rotation)
        self.pose: tuple[float, float] | None = None
        self.goal: str | None = None  # waypoint of the goal awaiting its response
        self.failed: str | None = None  # waypoint whose goal failed last
        self.approach = False
        self.dock: str | None = None  # the latest dock/undock command
        self.dock_failed: str | None = None
        self.asked = False
        self.stream_on = False
        self.samples: list[tuple[float, float]] = []  # (t, level) while the stream is on
        self.seq = 0  # the seq of the latest datagram out (the command after it is its)
        self.roles = roles if roles is not None else Reader(site).roles  # topic -> role
        self.operator: list[OperatorCall] = []
        self.alerts: list[AlertChange] = []
        self.metres: dict[int, float] = {}
        self.tree = ""
        self.last: float | None = None  # the latest item's time
        self.face_stops = {s.poi for s in site.tour.stops if s.face_stream}
        self.stop_of = stop_of(site)
        self.near = site.engagement.near
        self.edge = site.engagement.edge

    def first(self, t: float) -> None:
        """The file's first message: a piece opens, in case the file opens inside a tour."""
        self.piece = Piece(self.path, None, 0, t, t)
        self.out.append(self.piece)
        self.opening = True

    def finish(self) -> list[Piece]:
        """The pieces, but an opening one that held nothing of a tour (an idle file's)."""
        return [p for p in self.out if p.started is not None or p.of_a_tour()]

    def take(self, t: float, item: Item) -> None:
        """One item of the file (acks, ticks and bad messages tell nothing here)."""
        self.last = t
        match item:
            case RobotInput():
                self.robot_input(t, item)
            case RobotCommand():
                self.robot_command(t, item)
            case Datagram(direction="out", data=data):
                # its seq, through the front-end protocol: a new command's follows it
                with contextlib.suppress(DecodeError):
                    self.seq = decode_datagram(data).seq
            case FrontendOut(message=message):
                self.frontend_out(t, self.seq, message)
            case FrontendIn(message=message):
                self.frontend_in(t, message)
            case Primed():
                self.primed = True  # a rotated file (the reader took its seqs sent)
            case OperatorDone():
                self.operator_done(t, item)
            case AlertChanged(alert=alert):
                self.alerts.append(
                    AlertChange(
                        t,
                        alert.id,
                        alert.kind,
                        alert.state,
                        alert.severity,
                        alert.repeat,
                        alert.subject,
                    )
                )
            case Tree(xml=xml) if not self.tree:
                self.tree = hashlib.sha256(xml.encode()).hexdigest()[:12]

    def _current(self, t: float) -> Piece | None:
        """The piece open now (None between a tour's end and the next start), its last
        event moved to ``t``."""
        if self.piece is not None:
            self.piece.t1 = t
        return self.piece

    def _stop(self, poi: str) -> StopFacts | None:
        if self.piece is None:
            return None
        for stop in reversed(self.piece.stops):
            if stop.poi == poi:
                return stop
        return None

    def frontend_out(self, t: float, seq: int, message: FrontendMessage) -> None:
        """A new command (the reader tells a resend from one) and its seq."""
        if isinstance(message, Tour):
            self._tour(t, seq, message)
            return
        piece = self._current(t)
        if piece is None:
            return
        if isinstance(message, StartPoi):
            poi, part = message.poi, message.part
            stop = self._stop(poi)
            if part == "a" or stop is None:
                stop = StopFacts(poi, message.waypoint or poi, face_stream=poi in self.face_stops)
                piece.stops.append(stop)
                stop.start = t
            if part not in stop.parts:
                stop.parts += part
            if part == "b":
                self._engagement(stop, t)
        elif isinstance(message, FinishPoi):
            stop = self._stop(message.poi)
            if stop is not None:
                stop.end = t
                if "b" not in stop.parts:
                    self._engagement(stop, t)
        elif isinstance(message, AskTour):
            self.asked = True
            piece.invitations += 1

    def _tour(self, t: float, seq: int, message: Tour) -> None:
        state = TourState(message.state)
        if state is TourState.STARTED:
            self._started(t, seq)
            return
        piece = self._current(t)
        if piece is not None:  # (None: said again after the tour's end)
            piece.ended, piece.reason, piece.end_seq = state.value, message.reason, seq
            if state is TourState.ABORTED:
                self.back = piece  # the robot returns to its dock: still this tour's
        if piece is not None and self.opening:
            # A tour file has no primer: this may be the tour before's end, resent
            # (rows.join tells by its seq); what follows goes into a new opening
            # piece, in case it is the open tour's.
            self.piece = Piece(self.path, None, 0, t, t)
            self.out.append(self.piece)
        else:
            self.piece, self.opening = None, False

    def _started(self, t: float, seq: int) -> None:
        piece = self.piece
        if piece is not None and not self.opening:
            return  # said again (a resend taken anew): the same tour
        if piece is not None and not piece.of_a_tour():
            self.out.remove(piece)  # an idle file's opening: no tour
        self.back = None
        self.piece = Piece(self.path, t, seq, t, t)
        self.out.append(self.piece)
        self.opening = False

    def _engagement(self, stop: StopFacts, t: float) -> None:
        """The face samples stored since the stop's start, and the edge vote over them
        (:func:`frog_bt.maths.engagement.decide`, the executive's own rule)."""
        if not stop.face_stream or stop.start is None:
            return
        end = stop.a_end if stop.a_end is not None else t
        levels = [level for ts, level in self.samples if ts <= end]  # since the stream began
        stop.samples = len(levels)
        if levels:
            d = decide(np.asarray(levels), self.edge)
            stop.edge_engaged, stop.edge_total = d.engaged_votes, d.votes

    def frontend_in(self, t: float, message: FrontendMessage) -> None:
        if isinstance(message, ContentDone) and message.part == "a":
            stop = self._stop(message.poi)
            if stop is not None and stop.a_end is None:
                stop.a_end = t  # the decision counts the samples up to here
        if (
            isinstance(message, UserPositive | UserNegative)
            and self.piece is not None
            and self.asked
        ):
            self.asked = False
            piece = self.piece
            if isinstance(message, UserPositive):
                piece.accepted += 1
                if piece.approached:
                    piece.visitors.append(piece.approached[-1])
            else:
                piece.declined += 1

    def robot_command(self, t: float, command: RobotCommand) -> None:
        # the drive back after an abort is the aborted tour's
        piece = self.back if self.back is not None else self.piece
        role, value = command.role, command.value
        if role == "goto" and isinstance(value, Pose):
            goal, self.approach = self.site.waypoint_of(value), False
            if piece is not None:
                piece.goals += 1
                piece.nav_retries += goal == self.failed
                piece.t1 = t
            self.goal, self.failed = goal, None
        elif role == "approach" and isinstance(value, int):
            self.approach, self.goal = True, None
            piece = self.piece
            if piece is not None:
                piece.approaches += 1
                piece.approached.append(value)
                piece.t1 = t
        elif role == "dock" and isinstance(value, str):
            if piece is not None and value == self.dock_failed:
                piece.dock_retries += 1
            self.dock, self.dock_failed = value, None
        elif role == "icl":
            on = value == FaceStream.START
            if on and not self.stream_on:
                self.samples = []
            self.stream_on = on

    def robot_input(self, t: float, received: RobotInput) -> None:
        piece = self.back if self.back is not None else self.piece
        role, value = self.roles.get(received.topic), received.value
        if role == "pose" and isinstance(value, Pose):
            if self.pose is not None:
                step = math.hypot(value.x - self.pose[0], value.y - self.pose[1])
                if 0.0 < step < JUMP:
                    hour = int(t // HOUR)
                    self.metres[hour] = self.metres.get(hour, 0.0) + step
                    if piece is not None:
                        piece.distance += step
            self.pose = (value.x, value.y)
        elif role == "response" and isinstance(value, int):
            self._response(Response.of(value), piece)
        elif role == "docking_state" and isinstance(value, str):
            state = DockingState.of(value)
            if state in (DockingState.DOCKING, DockingState.UNDOCKING):
                # what is under way (a file may open here)
                self.dock = (
                    DockCommand.DOCK if state is DockingState.DOCKING else DockCommand.UNDOCK
                )
            elif state is DockingState.FAILED and self.dock is not None:
                self.dock_failed = self.dock
            elif state is DockingState.DOCKED and self.back is not None:
                self.back.t1, self.back = t, None  # home after the abort: the tour is over
        elif role == "faces" and self.stream_on and isinstance(value, FaceData):
            self.samples.extend(
                (t, face.engagement)
                for face in value.faces
                if face.distance <= self.near and face.facing
            )
        elif role == "diagnostic" and piece is not None and isinstance(value, Diagnostics):
            for status in value.statuses:
                if status.level == DiagnosticLevel.ERROR:
                    fault = (status.name, status.message)
                    if fault not in piece.faults:
                        piece.faults.append(fault)

    def _response(self, response: Response | None, piece: Piece | None) -> None:
        """A goal's or an approach's end (an active or unknown code changes nothing)."""
        if response is None or not response.terminal:
            return
        if self.approach:
            self.approach = False
            if piece is not None:
                if response is SUCCEEDED:
                    piece.approaches_ok += 1
                else:
                    piece.approaches_rejected += 1
        elif self.goal is not None:
            if response is not SUCCEEDED:
                self.failed = self.goal
                if piece is not None:
                    piece.failed_goals.append(self.goal)
            self.goal = None

    def operator_done(self, t: float, done: OperatorDone) -> None:
        """An operator command, in or out of a tour (rows assign operator commands and
        alert changes to tours by time: an alert raised as a tour aborts is raised on the
        drive home)."""
        self.operator.append(OperatorCall(t, done.command, done.ok, done.text, done.id, done.by))
        piece = self.back if self.back is not None else self.piece
        if piece is not None and done.command == OperatorCommand.SKIP and done.ok:
            at = self._skipping()
            if at is not None:
                piece.operator_skips.append(at)

    def _skipping(self) -> str | None:
        """The stop an operator's skip leaves: the one playing, or the one driven to."""
        if self.piece is None:
            return None
        stops = self.piece.stops
        if stops and stops[-1].end is None:
            return stops[-1].poi
        return self.stop_of.get(self.goal) if self.goal is not None else None


def read_file(path: str, site: Site) -> FileFacts:
    """The tour pieces in one recording; any failure is an unreadable file, never a crash."""
    try:
        recording = open_recording(Path(path))
        if FRONTEND_OUT not in recording.types:
            return FileFacts(path, error=f"not a frog-bt tour recording (no {FRONTEND_OUT})")
        reader = Reader(site, only={*(site.topic(role) for role in ROS_ROLES), *OWN})
        pieces = _Pieces(path, site, reader.roles)
        start = from_ns(recording.start) if recording.start or recording.end else None
        if start is not None:
            pieces.first(start)
        for t, item in reader.read(recording):
            pieces.take(t, item)
        # An executive's first file: neither a tour file nor an idle file it rotated into
        # (those open with a primer); a file without our metadata is one whole run.
        kind = recording.metadata.get("frog_bt", {}).get("kind")
        restarts = [start] if start is not None and kind != "tour" and not pieces.primed else []
        tally = reader.tally
        run = read_metadata(recording.metadata)
        return FileFacts(
            path,
            pieces.finish(),
            restarts,
            end=pieces.last if pieces.last is not None else (start or 0.0),
            operator=pieces.operator,
            alerts=pieces.alerts,
            metres=pieces.metres,
            library=_library(Path(path)),
            tree=pieces.tree,
            config=recording.metadata.get(SITE_METADATA, {}).get("config_sha256", ""),
            run=run.id,
            robot_name=run.robot,
            recovered=recording.recovered,
            start=start or 0.0,
            bad=tally.count,
            bad_first=tally.lines(start or 0.0)[:BAD_NOTED],
        )
    except RecordingError as exc:
        return FileFacts(path, error=str(exc).replace(f"{path}: ", ""))
    except Exception as exc:  # a damaged file must not stop the corpus
        return FileFacts(path, error=f"{type(exc).__name__}: {exc}".splitlines()[0][:200])


def _library(path: Path) -> str:
    """The MCAP header's ``library`` (``frog-bt 0.1.0``): which version wrote the file."""
    try:
        from mcap.reader import make_reader

        with open(path, "rb") as stream:
            return str(make_reader(stream).get_header().library)
    except Exception:  # a damaged header: the version is unknown, the file still read
        return ""
