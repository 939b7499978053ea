"""One warning per kind per interval: a flood of bad input costs a log line, not a disk.

Warnings held back in between are counted and reported with the next one that
gets through. The one rate-limiter of the project: the rosbridge client, the
front-end link and the executive's checkpoint writer all use it.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

WARN_INTERVAL = 5.0  # wall seconds between two warnings of one kind


class WarningLimiter:
    """At most one warning per kind per ``interval`` seconds of ``wall`` time."""

    def __init__(
        self,
        interval: float = WARN_INTERVAL,
        wall: Callable[[], float] = time.monotonic,
        logger: logging.Logger | None = None,
    ) -> None:
        self.interval = interval
        self._wall = wall
        self._log = logger or logging.getLogger(__name__)
        self._last: dict[str, float] = {}
        self._held: dict[str, int] = {}

    def allow(self, kind: str, now: float | None = None) -> int | None:
        """None: stay quiet. Otherwise log, noting this many held back since the last."""
        now = self._wall() if now is None else now
        last = self._last.get(kind)
        if last is not None and now - last < self.interval:
            self._held[kind] = self._held.get(kind, 0) + 1
            return None
        self._last[kind] = now
        return self._held.pop(kind, 0)

    def flush(self) -> int:
        """Log, one line per kind, the warnings held back since their last line (at close:
        a flood's last ones would otherwise never be told); how many lines were logged."""
        held, self._held = self._held, {}
        for kind, count in held.items():
            if count:
                self._log.warning("%d more %s suppressed before the end", count, kind)
        return sum(1 for count in held.values() if count)

    def warn(self, kind: str, message: str) -> bool:
        """Log ``message`` unless ``kind`` was logged within the interval; True if logged."""
        held = self.allow(kind)
        if held is None:
            return False
        self._log.warning("%s", f"{message} ({held} more {kind} suppressed)" if held else message)
        return True
