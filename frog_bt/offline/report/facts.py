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

What a piece counts (stops reached, played and skipped, goals, visitors, ...) is the one
count of tours, :class:`~frog_bt.model.ledger.TourLedger`, fed the file's events; the
piece boundaries above are the ledger's rows.

Channels read, through the one decoder of recordings (:mod:`frog_bt.recordings.reader`),
as the executive's events it gives back: ``/frontend/out`` (tour, start_poi, finish_poi,
ask_tour: its new commands, and the seq of each), ``/frontend/in`` (user_positive/negative,
content_done), ``/GotoWayPoint``, ``/ApproachPeopleFar``,
``/FROG_response``, ``/docking/dock``, ``/docking/state``, ``/ICL_command``,
``/ICL_FaceDataStream``, ``/FROG_pose``, ``/diagnostic``, ``/frog_bt/operator``,
``/frog_bt/alert``, ``/frog_bt/doubt`` and ``/frog_bt/primer`` (a rotated file: the reader
takes the front-end seqs sent just before it, so that a resend across the rotation is not
taken for a new command). Topic
names are the site's. A message that does not decode is counted (:attr:`FileFacts.bad`)
and read past.
"""

from __future__ import annotations

import contextlib
import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from frog_bt.config import Site
from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import decode_datagram
from frog_bt.model.channels import (
    ALERT,
    DOUBT,
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
    Event,
    FrontendOut,
    OperatorDone,
    RobotInput,
)
from frog_bt.model.frontend import Tour
from frog_bt.model.ledger import TourLedger, step
from frog_bt.model.outcomes import TourState
from frog_bt.model.ros import Pose
from frog_bt.model.run import read_metadata
from frog_bt.model.tours import TourRow
from frog_bt.recordings.mcapfile import RecordingError, open_recording
from frog_bt.recordings.reader import Item, Primed, Reader

OWN = (FRONTEND_IN, FRONTEND_OUT, OPERATOR, ALERT, DOUBT, PRIMER, TREE)
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
class Piece(TourRow):
    """One tour, or the part of one that a file holds: the ledger's row, and where it
    was read (the front-end seqs of its start and end tell a resend in the next file)."""

    file: str = ""
    started_seq: int = 0  # the seq of its `tour started`: a resend of it is no new tour
    end_seq: int = 0  # the seq of its `tour ended`/`aborted`


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
    return dict(site.tour_plan().waypoints)


class _Pieces:
    """One file's items, in time order (:meth:`take` each): its tours counted by the
    one ledger (:class:`~frog_bt.model.ledger.TourLedger`), and what the file holds
    besides (operator commands, alert changes, metres per hour, the tree)."""

    def __init__(self, path: str, site: Site) -> None:
        self.path = path
        self.ledger = TourLedger(site.tour_plan())
        self.primed = False  # the file opens with a /frog_bt/primer (an idle rotation)
        self.seq = 0  # the seq of the latest datagram out (the command after it is its)
        self.seqs: dict[int, tuple[int, int]] = {}  # id(row) -> (started seq, end seq)
        self.pose: tuple[float, float] | None = None
        self.operator: list[OperatorCall] = []
        self.alerts: list[AlertChange] = []
        self.metres: dict[int, float] = {}
        self.tree = ""
        self.last: float | None = None  # the latest item's time
        self.pose_topic = site.topic("pose")

    def first(self, t: float) -> None:
        """The file's first message: a row opens, in case the file opens inside a tour."""
        self.ledger.begin(t)

    def finish(self) -> list[Piece]:
        """The pieces, but an opening one that held nothing of a tour (an idle file's)."""
        out = []
        for row in self.ledger.tours:
            started, ended = self.seqs.get(id(row), (0, 0))
            out.append(Piece(**vars(row), file=self.path, started_seq=started, end_seq=ended))
        return out

    def take(self, t: float, item: Item) -> None:
        """One item of the file, in time order: every event to the ledger; besides, the
        seq of each datagram out (the new command the reader gives after it is its),
        metres driven, operator commands, alert changes and the tree."""
        self.last = t
        match item:
            case Datagram(direction="out", data=data):
                with contextlib.suppress(DecodeError):
                    self.seq = decode_datagram(data).seq
            case Primed():
                self.primed = True  # a rotated file (the reader took its seqs sent)
            case RobotInput(topic=topic, value=value) if topic == self.pose_topic:
                self._pose(t, value)
            case OperatorDone():
                self.operator.append(
                    OperatorCall(t, item.command, item.ok, item.text, item.id, item.by)
                )
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
        if not isinstance(item, Event):
            return
        before = self.ledger.current
        self.ledger.feed(item)
        if isinstance(item, FrontendOut) and isinstance(item.message, Tour):
            self._seq(self.seq, item.message, before)

    def _seq(self, seq: int, message: Tour, before: TourRow | None) -> None:
        """Note the seq of a tour's start or end on its row."""
        if message.state == TourState.STARTED:
            row = self.ledger.current
            if row is not None and row is not before:
                self.seqs[id(row)] = (seq, 0)
        elif before is not None and before.ended:
            started, _ = self.seqs.get(id(before), (0, 0))
            self.seqs[id(before)] = (started, seq)

    def _pose(self, t: float, value: object) -> None:
        """Metres driven per clock hour, in tours or not."""
        if not isinstance(value, Pose):
            return
        if self.pose is not None:
            metres = step(self.pose, value)
            if metres:
                hour = int(t // HOUR)
                self.metres[hour] = self.metres.get(hour, 0.0) + metres
        self.pose = (value.x, value.y)


def read_file(path: str, site: Site) -> FileFacts:
    """The tour pieces in one recording; any failure is an unreadable file, never a crash."""
    try:
        recording = open_recording(Path(path))
        if FRONTEND_OUT not in recording.types:
            return FileFacts(path, error=f"not a frog-bt tour recording (no {FRONTEND_OUT})")
        reader = Reader(site, only={*(site.topic(role) for role in ROS_ROLES), *OWN})
        pieces = _Pieces(path, site)
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
