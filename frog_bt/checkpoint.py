"""Tour progress, checkpointed to a small file so a restarted executive resumes the tour.

:class:`Progress` is the ordered list of checkpoints (``start``, ``recruit``,
``stop 0``, ``stop 1``, …) completed in the current tour, and the visitor being
guided. Starting a checkpoint again drops it and everything after it (a lost
visitor: recruit again, then every stop again). The executive writes the file
atomically (write a temporary file, fsync, rename) whenever progress changes,
and deletes it when a tour ends or is aborted.

On start-up, :func:`load` gives a :class:`Resume`: the checkpoints a resumed
tour skips, once each, and the visitor to restore.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

VERSION = 1


@dataclass
class Progress:
    done: list[str] = field(default_factory=list)
    visitor: int | None = None
    changes: int = 0  # bumped on every change, so the writer knows when to save

    def begin(self, name: str) -> None:
        if name in self.done:
            del self.done[self.done.index(name):]
            self.changes += 1

    def complete(self, name: str, visitor: int | None = None) -> None:
        if name not in self.done:
            self.done.append(name)
        if visitor is not None:
            self.visitor = visitor
        self.changes += 1

    def clear(self) -> None:
        if self.done or self.visitor is not None:
            self.done, self.visitor = [], None
            self.changes += 1

    def to_json(self) -> dict[str, object]:
        return {"version": VERSION, "done": list(self.done), "visitor": self.visitor,
                "written": time.time()}


@dataclass
class Resume:
    """What a restarted executive skips (each name once) and the visitor it restores."""

    done: set[str]
    visitor: int | None
    order: list[str] = field(default_factory=list)

    def describe(self) -> str:
        last = self.order[-1] if self.order else "nothing"
        return f"after {last}" + (f", visitor {self.visitor}" if self.visitor is not None else "")


def save(path: Path, progress: Progress) -> None:
    """Write ``progress`` atomically; an empty progress removes the file."""
    if not progress.done:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".checkpoint-", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(progress.to_json(), f)
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
    return Resume(set(done), visitor, list(done))
