"""Tour progress, checkpointed to a small file so a restarted executive resumes the tour.

:class:`~frog_bt.model.progress.Progress` (on the blackboard) is the ordered list of
checkpoints completed in the current tour, and the visitor being guided. The executive
writes the file
atomically (write a temporary file, fsync, rename) whenever progress changes,
and deletes it when a tour ends or is aborted.

On start-up, :func:`load` gives a :class:`Resume`: the checkpoints a resumed
tour skips, once each, the visitor to restore, the run id of the executive that
wrote it, which the resumed executive's recordings keep (:mod:`frog_bt.model.run`), and
the tour's row as the one count of tours had it (``tour``: its stops reached, played and
skipped, visitors, help and commands so far), which the resumed executive's count
carries on, so that it counts the tour as the report does over both executives' files.

No crash loop: a checkpoint says how often it was resumed without progress since
(:func:`mark_resumed`, reset by the next :func:`save`) and why the executive that ran it
crashed, if it did (:func:`mark_crashed`). A restarted executive that would resume the
same checkpoint into the same failure (:func:`crash_loop`) holds and asks a person
instead.

A checkpoint belongs to one executive. The default file is scoped by the site
configuration and the listen address (:func:`default_path`), and
:func:`claim` locks it for the executive's lifetime, so two executives on one
machine (two robots, or a test beside a live run) never resume each other's
tours.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import math
import os
import re
import tempfile
import time
from pathlib import Path
from typing import IO

from frog_bt.errors import UsageError
from frog_bt.model.progress import VERSION, Progress, Resume
from frog_bt.model.run import valid_id
from frog_bt.model.tours import TourRow
from frog_bt.text import LINE, inert

STATE_DIR = Path(os.environ.get("XDG_STATE_HOME", Path.home() / ".local" / "state")) / "frog-bt"

__all__ = [
    "RESUMES_WITHOUT_PROGRESS",
    "VERSION",
    "Progress",
    "Resume",
    "claim",
    "crash_loop",
    "default_path",
    "load",
    "mark_crashed",
    "mark_resumed",
    "save",
]

# Starts that resumed a checkpoint and stopped again before any progress (a kill, an
# out-of-memory, a watchdog): the next one does not resume it but holds and asks.
RESUMES_WITHOUT_PROGRESS = 2


def default_path(config: Path, listen: tuple[str, int], state_dir: Path = STATE_DIR) -> Path:
    """The checkpoint file of the executive of site ``config`` listening on ``listen``."""
    site = hashlib.sha256(str(config.resolve()).encode()).hexdigest()[:8]
    host = re.sub(r"[^\w.-]", "_", listen[0])
    return state_dir / f"checkpoint-{host}-{listen[1]}-{site}.json"


def claim(path: Path, option: str = "--checkpoint") -> IO[str]:
    """Lock ``path`` for this executive (held until the returned file is closed).

    Raises UsageError when the directory cannot be written or another running
    executive holds the checkpoint.
    """
    lock_path = path.with_name(path.name + ".lock")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle = open(lock_path, "a+", encoding="utf-8")  # noqa: SIM115 - held open
    except (FileExistsError, NotADirectoryError):
        raise UsageError(
            option, path, f"cannot write there: {path.parent} is not a directory"
        ) from None
    except OSError as exc:
        raise UsageError(option, path, f"cannot write there: {exc.strerror or exc}") from None
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.seek(0)
        holder = handle.read().strip() or "?"
        handle.close()
        raise UsageError(
            option,
            path,
            f"in use by another running executive (pid {holder}); "
            "give each executive its own --checkpoint",
        ) from None
    handle.seek(0)
    handle.truncate()
    handle.write(str(os.getpid()))
    handle.flush()
    return handle


def save(path: Path, progress: Progress, run: str = "", tour: TourRow | None = None) -> None:
    """Write ``progress`` of run ``run`` (its id) and the ``tour``'s row so far (the one
    count of tours') atomically; an empty progress removes the file."""
    data = {**progress.to_json(time.time()), "run": run}
    if tour is not None:
        data["tour"] = tour.to_json()
    write_json(path, data if progress.done else None)


def write_json(path: Path, data: object | None) -> None:
    """Write ``data`` as JSON to ``path`` atomically (a temporary file, fsync, rename): a
    kill or a power cut leaves the old file or the new one, never half of one. None
    removes the file."""
    if data is None:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}-", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(data, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def load(path: Path, max_age: float = math.inf) -> Resume | None:
    """The resume point in ``path``; None when there is none, it is unreadable, or it was
    written more than ``max_age`` wall seconds ago (a tour that old is over, whatever)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("version") != VERSION:
        return None
    written = data.get("written")
    if not isinstance(written, int | float) or not 0 <= time.time() - written <= max_age:
        return None
    done = data.get("done")
    visitor = data.get("visitor")
    if not isinstance(done, list) or not all(isinstance(d, str) for d in done) or not done:
        return None
    if visitor is not None and (isinstance(visitor, bool) or not isinstance(visitor, int)):
        visitor = None
    resumed = data.get("resumed", 0)
    resumed = resumed if isinstance(resumed, int) and not isinstance(resumed, bool) else 0
    crashed = data.get("crashed", "")
    crashed = inert(crashed, LINE) if isinstance(crashed, str) else "crashed"
    return Resume(
        frozenset(done),
        visitor,
        tuple(done),
        float(written),
        valid_id(data.get("run")),
        resumed,
        crashed,
        TourRow.of_json(data["tour"]) if "tour" in data else None,
    )


def _update(path: Path, **fields: object) -> None:
    """Add ``fields`` to the checkpoint in ``path`` (atomically); nothing without one."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    if isinstance(data, dict):
        write_json(path, {**data, **fields})


def mark_resumed(path: Path, resume: Resume) -> None:
    """This start resumes ``resume``: counted in the file until the tour makes progress
    (:func:`save` writes a checkpoint without the count)."""
    _update(path, resumed=resume.resumed + 1)


def mark_crashed(path: Path, why: str) -> None:
    """The executive running the tour of ``path`` crashed: say why, for the next start."""
    _update(path, crashed=inert(why, LINE))


def crash_loop(resume: Resume) -> str | None:
    """Why resuming ``resume`` would run into the same failure again, or None."""
    if resume.crashed:
        return f"it crashed on this tour: {resume.crashed}"
    if resume.resumed >= RESUMES_WITHOUT_PROGRESS:
        return f"it stopped {resume.resumed + 1} times on this tour without going on"
    return None
