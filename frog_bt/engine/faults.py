"""Failures of the executive's own code, caught where they happen and counted.

No input may stop the executive: an exception raised while a node ticks (its
``initialise``, ``update`` or ``terminate``), while an input is handled, or while an
observer hears an event is caught at that boundary and handed to :class:`Faults`. The
node's tick counts as its FAILURE (the tree goes on as it would after any failure); an
input that could not be handled is dropped; the executive runs on.

Each failure is *logged once* per place and kind (one line naming the node or the input
and the error, the text made inert; later ones are counted, not logged), *recorded*
(:class:`~frog_bt.model.events.Faulted` to the observers: the recording, telemetry) and
*counted*. A failure seen :data:`REPEATED` times at the same place is :meth:`repeated`:
the executive raises an alert for it (``internal_error``), which holds while it keeps
happening (for :data:`QUIET` seconds after the last one).
"""

from __future__ import annotations

import logging
import traceback
from collections.abc import Callable
from dataclasses import dataclass

from frog_bt.clock import Clock
from frog_bt.model.events import Faulted
from frog_bt.text import LINE, inert

log = logging.getLogger("frog_bt.faults")

REPEATED = 3  # failures at one place before the executive raises an alert
QUIET = 600.0  # seconds after the last failure at a place before its alert clears

__all__ = ["QUIET", "REPEATED", "Faults", "Seen"]


@dataclass(slots=True)
class Seen:
    """One place's failures: how many, the latest one's error and time."""

    where: str
    error: str
    count: int = 0
    last: float = 0.0


class Faults:
    """The failures of one executive's code (kept across tree reloads)."""

    def __init__(self, clock: Clock) -> None:
        self._clock = clock
        self.emit: Callable[[Faulted], None] | None = None  # the host's observers
        self.total = 0
        self.seen: dict[tuple[str, str], Seen] = {}

    def failed(self, where: str, exc: BaseException, what: str = "") -> Seen:
        """Note one failure at ``where`` (a node's name, ``input /diagnostic``, an
        observer's class); ``what`` says what was being done. Logged the first time for
        this place and kind of error, recorded and counted every time."""
        now = self._clock.now() if self._clock.ready else 0.0
        error = inert(f"{type(exc).__name__}: {exc}", LINE)
        key = (where, type(exc).__name__)
        seen = self.seen.get(key)
        if seen is None:
            seen = self.seen[key] = Seen(inert(where), error)
            frame = traceback.extract_tb(exc.__traceback__)[-1:] if exc.__traceback__ else []
            at = f" ({frame[0].filename.rsplit('/', 1)[-1]}:{frame[0].lineno})" if frame else ""
            log.error(
                "%s failed%s: %s%s; going on (further ones are counted)",
                seen.where,
                f" in {what}" if what else "",
                error,
                at,
            )
        seen.count += 1
        seen.error, seen.last = error, now
        self.total += 1
        if self.emit is not None:
            self.emit(Faulted(now, seen.where, what, error, seen.count))
        return seen

    def repeated(self, now: float) -> list[Seen]:
        """The places that failed :data:`REPEATED` times or more, the latest within
        :data:`QUIET` seconds of ``now``: what an alert should say."""
        return [s for s in self.seen.values() if s.count >= REPEATED and now - s.last <= QUIET]
