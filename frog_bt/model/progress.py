"""Tour progress and the resume point of a restarted executive, as immutable values.

:class:`Progress` is the ordered list of checkpoints (``start``, ``recruit``, ``stop 0``,
…) completed in the current tour, and the visitor being guided; it lives on the
blackboard (:data:`frog_bt.model.keys.PROGRESS`), and the executive writes it to the
checkpoint file whenever a tick leaves a new value there
(:mod:`frog_bt.runtime.checkpoint`). Starting a checkpoint again drops it and everything
after it (a lost visitor: recruit again, then every stop again).

:class:`Resume` is what a restarted executive skips (each name once), the visitor it
restores (:data:`frog_bt.model.keys.RESUME`), the run it carries on
(:mod:`frog_bt.model.run`) and the tour's row so far, as the one count of tours had it
when the checkpoint was written (:class:`~frog_bt.model.tours.TourRow`: the resumed
executive's count carries it on, :meth:`~frog_bt.model.ledger.TourLedger.resume`).
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, replace

from frog_bt.model.tours import TourRow

VERSION = 1


@dataclass(frozen=True, slots=True)
class Progress:
    done: tuple[str, ...] = ()
    visitor: int | None = None

    def begin(self, name: str) -> Progress:
        """Progress once ``name`` starts (again): it and every later checkpoint dropped."""
        if name not in self.done:
            return self
        return replace(self, done=self.done[: self.done.index(name)])

    def complete(self, name: str, visitor: int | None = None) -> Progress:
        done = self.done if name in self.done else (*self.done, name)
        return Progress(done, self.visitor if visitor is None else visitor)

    def to_json(self, written: float) -> dict[str, object]:
        return {
            "version": VERSION,
            "done": list(self.done),
            "visitor": self.visitor,
            "written": written,
        }


EMPTY = Progress()


@dataclass(frozen=True, slots=True)
class Resume:
    """What a restarted executive skips (each name once) and the visitor it restores."""

    done: frozenset[str]
    visitor: int | None
    order: tuple[str, ...] = ()
    written: float = 0.0  # wall time the checkpoint was written
    run: str = ""  # the run id of the executive that wrote it ("": not recorded)
    resumed: int = 0  # starts that resumed it and then stopped before any progress
    crashed: str = ""  # why the executive that ran it crashed (empty: it did not)
    tour: TourRow | None = None  # the tour so far, as counted then (None: not kept)

    def without(self, name: str) -> Resume:
        """This resume point once ``name`` has been skipped."""
        return replace(self, done=self.done - {name})

    def describe(self) -> str:
        last = self.order[-1] if self.order else "nothing"
        return f"after {last}" + (f", visitor {self.visitor}" if self.visitor is not None else "")

    def announce(self, stops: list[str], now: float | None = None) -> str:
        """``resuming the tour at POI4: checkpoint 3 min old`` (``stops``: the tour's POIs)."""
        return f"resuming the tour {self.where(stops)}: checkpoint {self.age_text(now)} old"

    def where(self, stops: list[str]) -> str:
        """Where the resumed tour picks up, in the tour's words."""
        done_stops = [int(n.split()[1]) for n in self.order if re.fullmatch(r"stop \d+", n)]
        if done_stops:
            following = max(done_stops) + 1
            return (
                f"at {stops[following]}"
                if following < len(stops)
                else "on the way back to the dock"
            )
        if "recruit" in self.order:
            return f"at {stops[0]}" if stops else "after recruiting"
        return "at the recruitment"

    def age_text(self, now: float | None = None) -> str:
        age = max(0.0, (time.time() if now is None else now) - self.written)
        return f"{age:.0f} s" if age < 90 else f"{age / 60:.0f} min"
