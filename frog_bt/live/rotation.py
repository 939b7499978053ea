"""``frog-bt run --record DIR``: a day of recordings, one file per tour and idle period.

:class:`RecordingDir` keeps one :class:`~frog_bt.live.recording.Recorder` and moves
it to a new file at two points, always between ticks:

* when a tour starts (the tree's ``TourStatus started``): the idle period before it
  ends, ``…-tourNNNN.mcap`` begins. The tree is mid-run there, so the tour file's
  metadata names the idle file as its ``lead_in``; ``frog-bt replay`` reads the two
  in turn.
* when the tree's run ends (the root ends: the tour is over, docked, or aborted
  and back at the dock): ``…-idleNNNN.mcap`` begins, for the next tour. The tree
  starts again from its root there, and the tree check guarantees every key it
  reads is written first in a run (``frog-bt check``), so the file needs only
  what the executive carries across runs: it starts with a ``/frog_bt/primer``
  (the latest message of every input, whether the front end said idle, the
  recent datagrams, and beside the tree the staff's decisions and the alert book)
  and replays on its own.

Files are named by their start time (site local time) and tour number,
``20260601-103012-tour0003.mcap``; numbers go on from the highest in DIR, so a
restarted executive does not reuse one. Each file has its summary and footer
once it is closed; one cut short (kill -9, power loss) loses at most the last
second (:data:`~frog_bt.live.recording.FLUSH_EVERY`) and replay recovers it.

The disk budget (``recording.max_bytes``): after each rotation, while DIR's
recordings add up to more, the oldest tour number's files (its idle file and
its tour file) are deleted, never the file being written; each deletion is
logged.
"""

from __future__ import annotations

import logging
import re
import time
from datetime import datetime
from pathlib import Path
from typing import Any

import py_trees

from frog_bt.clock import SITE_TZ
from frog_bt.engine.core import Core
from frog_bt.live.recording import Recorder
from frog_bt.model import keys
from frog_bt.model.events import Event, Ticked
from frog_bt.model.outcomes import TourState
from frog_bt.runtime.observer import Host
from frog_bt.runtime.staff import Staff

log = logging.getLogger(__name__)
Status = py_trees.common.Status
NAME = re.compile(r"^\d{8}-\d{6}-(idle|tour)(\d{4,})\.mcap$")


def numbered(directory: Path) -> list[tuple[int, Path]]:
    """The recordings in ``directory`` this module named, as (tour number, path), oldest
    first."""
    out = []
    for path in directory.glob("*.mcap"):
        match = NAME.match(path.name)
        if match:
            out.append((int(match.group(2)), path))
    return sorted(out, key=lambda item: (item[0], item[1].name))


class RecordingDir:
    """Rotating recordings in ``directory`` within ``max_bytes``; see the module docstring.

    ``RecordingDir(directory, max_bytes)`` creates the directory if needed;
    :meth:`attach` opens the first (idle) file; :meth:`close` finishes the current one.
    """

    def __init__(self, directory: Path, max_bytes: int) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.max_bytes = max_bytes
        taken = numbered(self.directory)
        self.number = taken[-1][0] + 1 if taken else 1
        self.kind = "idle"
        self.recorder: Recorder | None = None
        self.deleted: list[Path] = []
        self.files: list[Path] = []  # written by this run, in order
        self._clock: Any = None
        self._tour_state: TourState | None = None
        self._named_by_clock = False
        self._host: Host | None = None

    @property
    def path(self) -> Path | None:
        return self.recorder.path if self.recorder is not None else None

    def _name(self, kind: str) -> Path:
        clock = self._clock
        t = clock.now() if clock is not None and clock.ready else time.time()
        stamp = datetime.fromtimestamp(t, SITE_TZ).strftime("%Y%m%d-%H%M%S")
        return self.directory / f"{stamp}-{kind}{self.number:04d}.mcap"

    def attach(self, host: Host) -> None:
        self._clock = host.clock
        self._named_by_clock = bool(host.clock.ready)
        path = self._name("idle")
        self.recorder = Recorder(path, metadata={"kind": "idle", "tour": str(self.number)})
        self.files.append(path)
        self.recorder.attach(host)
        self._host = host

    def on_event(self, event: Event) -> None:
        """Into the file being written now; after a tick (in it now), rotate if a tour
        started or the tree's run ended."""
        recorder = self.recorder
        if recorder is not None:
            recorder.on_event(event)
        if type(event) is Ticked and self._host is not None:
            self.on_tick(self._host.core)

    def on_tick(self, core: Core) -> None:
        """Between ticks: a tour started, or the tree's run ended."""
        if not self._named_by_clock:
            self._rename_first()
        state, before = core.board.get(keys.TOUR_STATE), self._tour_state
        self._tour_state = state
        if self.kind == "idle" and state is TourState.STARTED and before is not TourState.STARTED:
            lead_in = self.path.name if self.path is not None else ""
            self._rotate(
                "tour", {"kind": "tour", "tour": str(self.number), "lead_in": lead_in}, None
            )
        elif core.root.status == Status.SUCCESS:
            if self.kind == "tour":
                self.number += 1
            assert self.recorder is not None
            staff = getattr(self._host, "staff", None)  # the executive's (a host may have none)
            primer = self.recorder.primer(
                bool(core.board.get(keys.FRONTEND_READY)),
                staff.carried() if isinstance(staff, Staff) else None,
            )
            self._rotate("idle", {"kind": "idle", "tour": str(self.number)}, primer)

    def _rename_first(self) -> None:
        """Under sim time the first file is opened before /clock: name it by the clock's
        time once there is one (the open file keeps being written under its new name)."""
        self._named_by_clock = True
        recorder = self.recorder
        if recorder is None or recorder.closed:
            return
        path = self._name("idle")
        try:
            recorder.path.rename(path)
        except OSError as exc:
            log.warning("recording: cannot rename %s to %s: %s", recorder.path, path.name, exc)
            return
        recorder.path = path
        self.files[-1] = path

    def _rotate(self, kind: str, metadata: dict[str, str], primer: bytes | None) -> None:
        recorder = self.recorder
        if recorder is None or recorder.closed:
            return
        path = self._name(kind)
        recorder.rotate(path, metadata, primer)
        self.kind = kind
        self.files.append(path)
        self.enforce_budget()

    def enforce_budget(self) -> None:
        """Delete the oldest tour numbers' files while DIR is over budget."""
        current = self.path
        files = numbered(self.directory)
        sizes = {path: _size(path) for _, path in files}
        total = sum(sizes.values())
        by_number: dict[int, list[Path]] = {}
        for number, path in files:
            by_number.setdefault(number, []).append(path)
        for _number, paths in sorted(by_number.items()):
            if total <= self.max_bytes:
                return
            if current in paths:
                log.warning(
                    "recording budget %d bytes: %s alone is over it; nothing older left to delete",
                    self.max_bytes,
                    current,
                )
                return
            for path in paths:
                try:
                    path.unlink()
                except OSError as exc:
                    log.error("recording budget: cannot delete %s: %s", path, exc)
                    continue
                total -= sizes[path]
                self.deleted.append(path)
                log.warning(
                    "recording budget %d bytes: deleted %s (%d bytes)",
                    self.max_bytes,
                    path.name,
                    sizes[path],
                )

    def close(self) -> None:
        if self.recorder is not None:
            self.recorder.close()


def _size(path: Path) -> int:
    try:
        return path.stat().st_size
    except OSError:
        return 0
