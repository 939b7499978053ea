"""What outlives the process: the tour's checkpoint and what staff decided, kept on disk.

A :class:`Keeper` is an observer of the executive. Attached (before any recorder: what it
takes up is recorded as the executive's ``restored``), it takes up what the files beside
``path`` say, unless ``fresh``:

* the checkpoint (:mod:`frog_bt.runtime.checkpoint`): its resume point goes on the board
  (``keys.RESUME``) and the run goes on under its id; unless resuming it would run into the
  same failure again (:func:`~frog_bt.runtime.checkpoint.crash_loop`): then the checkpoint
  is set aside (``.crashed``) and the robot holds and asks a person (``help`` crashed);
* what staff decided (:mod:`frog_bt.runtime.decisions`): out of service, a pause, the help
  the robot waits for, the alerts acknowledged, back into the staff's hands.

Then, after each tick (:class:`~frog_bt.model.events.Ticked`), it writes whichever of the
two changed; a write that fails (a full disk) is warned about once a minute and never
stops the tour. :meth:`Keeper.crashed` marks the checkpoint when the executive crashes, so
that the next start does not loop into the same failure (the command that runs the
executive calls it).
"""

from __future__ import annotations

import contextlib
import logging
from dataclasses import replace
from pathlib import Path

from frog_bt.model import keys
from frog_bt.model.channels import Restored
from frog_bt.model.events import Event, Ticked
from frog_bt.model.help import Help, HelpAbout
from frog_bt.model.progress import EMPTY, Progress, Resume
from frog_bt.model.run import RunId
from frog_bt.runtime import checkpoint, decisions
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.observer import Host
from frog_bt.warning_limit import WarningLimiter

__all__ = ["Keeper"]

log = logging.getLogger(__name__)


class Keeper:
    """Keeps ``path`` (the checkpoint) and the staff's file beside it; see the module."""

    def __init__(self, path: Path, *, fresh: bool = False) -> None:
        self.path = path
        self.fresh = fresh
        self.restored: Restored | None = None  # what it took up, as recorded
        self._host: Executive | None = None
        self._saved: Progress = EMPTY
        self._decided = decisions.NONE  # what staff decided, as last saved
        self._warnings = WarningLimiter(60.0, logger=log)

    def attach(self, host: Host) -> None:
        """Take up what the files say (not when ``fresh``), on ``host``'s board and staff
        (``host``: the online executive; a replay takes up what was recorded instead)."""
        if not isinstance(host, Executive):
            raise TypeError(f"a Keeper keeps an executive's files, not a {type(host).__name__}'s")
        self._host = host
        if self.fresh:
            return
        crash_loop: Help | None = None
        resume = checkpoint.load(self.path, host.site.checkpoint.max_age)
        if resume is not None:
            why = checkpoint.crash_loop(resume)
            if why is None:
                self._resume(host, resume)
            else:
                log.error("not resuming the tour of %s: %s; holding for a person", self.path, why)
                with contextlib.suppress(OSError):
                    self.path.replace(self.path.with_name(self.path.name + ".crashed"))
                crash_loop = Help(HelpAbout.CRASHED, resume.written, why)
                resume = None
        self._decided = decisions.load(decisions.path_for(self.path))
        if crash_loop is not None:  # it holds and asks, whatever staff decided
            self._decided = replace(self._decided, help=crash_loop)
        host.staff.restore(self._decided)
        if self._decided != decisions.NONE:
            log.info("restored what staff decided: %s", self._decided.to_json())
        # what this executive took up from before it: recorded, so that replay does too
        self.restored = host.restored = decisions.restored(resume, self._decided)

    def _resume(self, host: Executive, resume: Resume) -> None:
        """Resume ``resume`` (the file marked: resumed once more)."""
        checkpoint.mark_resumed(self.path, resume)
        host.core.board.set(keys.RESUME, resume)
        if resume.run:  # the run goes on: its recordings say so
            host.standing.run = RunId.resuming(resume.run)

    def on_event(self, event: Event) -> None:
        if isinstance(event, Ticked):
            self.keep()

    def close(self) -> None:
        """Nothing to finish: every change is written as it happens."""

    # ------------------------------------------------------------ writing

    def decided(self) -> decisions.Decisions:
        """What staff decided now, as it would be saved."""
        assert self._host is not None
        board = self._host.core.board
        help_ = board.get(keys.HELP) or board.get(keys.HELP_RESTORED)
        return decisions.Decisions(
            in_service=board.get(keys.IN_SERVICE) is not False,
            paused=bool(board.get(keys.PAUSED)),
            help=help_,
            acknowledged=self._host.staff.acknowledged_ids(),
        )

    def kept(self) -> bool:
        """True when the files say what the executive holds now."""
        assert self._host is not None
        progress = self._host.core.board.get(keys.PROGRESS) or EMPTY
        return progress == self._saved and self.decided() == self._decided

    def keep(self) -> None:
        """Write the checkpoint and the staff's decisions, each if it changed."""
        host = self._host
        if host is None:
            return
        progress = host.core.board.get(keys.PROGRESS) or EMPTY
        if progress != self._saved:
            self._saved = progress
            try:
                checkpoint.save(self.path, progress, host.standing.run.id, host.ledger.current)
            except OSError as exc:  # a full disk must not stop the tour; warn once a minute
                self._warnings.warn(
                    "checkpoint", f"cannot write the checkpoint {self.path}: {exc.strerror or exc}"
                )
        decided = self.decided()
        if decided != self._decided:
            self._decided = decided
            try:
                decisions.save(decisions.path_for(self.path), decided)
            except OSError as exc:
                self._warnings.warn(
                    "decisions", f"cannot keep what staff decided: {exc.strerror or exc}"
                )

    def crashed(self, exc: BaseException) -> None:
        """The executive crashed with ``exc``: the next start must not loop into it."""
        checkpoint.mark_crashed(self.path, f"{type(exc).__name__}: {exc}")
