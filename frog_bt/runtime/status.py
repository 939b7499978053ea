"""The live one-line status: phase, POI, stops, tree tip, visitor, battery — or the links.

The stops (``stops 2 of 6``: reached of the tour's content stops) are the one count of
tours' (:class:`~frog_bt.model.ledger.TourLedger`), as the console and the report count
(a resumed tour's stops before the restart too: :mod:`frog_bt.runtime.resuming`).

While rosbridge is unreachable (or, on sim time, no ``/clock`` has come) the line
says so instead of showing a tree that cannot tick::

    rosbridge: connecting to ws://frog:9090 (attempt 4, next in 2.0 s): connection refused

On a terminal the line is redrawn in place (at most every ``interval`` wall
seconds); elsewhere a line is printed only when it changes.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

import py_trees

from frog_bt.engine.core import Core
from frog_bt.engine.walk import running_path
from frog_bt.i18n import say
from frog_bt.model import keys
from frog_bt.model.events import Event, Ticked
from frog_bt.model.ledger import TourLedger
from frog_bt.rosbridge.link import LinkState
from frog_bt.runtime.observer import Host
from frog_bt.runtime.phrase import doing
from frog_bt.runtime.resuming import ResumingLedger


def phase(core: Core) -> str:
    """The running child of the first sequence on the running path: the tour's phase (the
    root's status in words when nothing runs)."""
    parent: py_trees.behaviour.Behaviour | None = None
    for node in running_path(core.root):
        if isinstance(parent, py_trees.composites.Sequence):
            return node.name
        parent = node
    assert parent is not None  # the path holds the root at least
    return str(parent.status.value).lower()


MILESTONES = (1, 2, 5)  # x 10^n: the attempt counts a journal hears of


def milestone(attempt: int) -> int:
    """The last of 1, 2, 5, 10, 20, 50, 100, ... at or below ``attempt`` (0 for 0)."""
    if attempt < 1:
        return 0
    scale, last = 1, 1
    while True:
        for m in MILESTONES:
            if m * scale > attempt:
                return last
            last = m * scale
        scale *= 10


def link_line(
    url: str,
    link: LinkState,
    clock_ready: bool = True,
    now: float | None = None,
    countdown: bool = True,
) -> str | None:
    """What the rosbridge link is doing, while it keeps the tree from running; else None.
    ``now``: the monotonic time the countdown is counted from (default: now). Without
    ``countdown`` (a journal, not a terminal) the line is a state: no "next in", and the
    attempt count only at growing steps (1, 2, 5, 10, 20, 50, ...)."""
    if link.connected:
        return None if clock_ready else f"rosbridge: connected to {url}, waiting for /clock"
    attempt = link.attempt if countdown else milestone(link.attempt)
    now = time.monotonic() if now is None else now
    retry_in = None if link.retry_at is None or not countdown else max(0.0, link.retry_at - now)
    detail = ", ".join(
        part
        for part in (
            (f"attempt {attempt}" if countdown else f"{attempt}+ attempts") if attempt else "",
            f"next in {retry_in:.1f} s" if retry_in is not None else "",
        )
        if part
    )
    error = _plain_error(link.last_error) if link.last_error else ""
    return (
        f"rosbridge: connecting to {url}"
        + (f" ({detail})" if detail else "")
        + (f": {error}" if error else "")
    )


def _plain_error(error: str) -> str:
    """``ConnectionRefusedError: [Errno 111] Connect call failed ...`` -> ``connection refused``."""
    lowered = error.lower()
    for needle, words in (
        ("authentication refused", "closed at once: authentication refused? (check the secret)"),
        ("refused", "connection refused"),
        ("timed out", "timed out"),
        ("name or service not known", "unknown host"),
        ("no route", "no route to host"),
        ("unreachable", "unreachable"),
    ):
        if needle in lowered:
            return words
    return error[:80]


def stops_part(ledger: TourLedger) -> str | None:
    """``stops 2 of 6`` while a tour is open (reached of the content stops), else None."""
    row = ledger.current
    if row is None or (row.started is None and not row.of_a_tour()):
        return None
    order = ledger.plan.content
    reached = {p for p in row.reached if p in order}
    return f"stops {len(reached)} of {len(order)}"


def status_line(core: Core, ledger: TourLedger | None = None) -> str:
    tip = core.root.tip()
    board = core.board
    diagnostics = board.get(keys.DIAGNOSTICS)
    battery = diagnostics.value.battery if diagnostics is not None else None
    visitor = board.get(keys.VISITOR)
    stops = stops_part(ledger) if ledger is not None else None
    parts = [
        say(doing(core), core.site.language),  # in the staff's words
        f"poi {board.get(keys.WAYPOINT) or '-'}",
        *([stops] if stops else []),
        f"tip {tip.name if tip else '-'}",
        f"visitor {visitor if visitor is not None else '-'}",
        f"battery {battery:.0f}%" if battery is not None else "battery -",
    ]
    resumed = board.get(keys.RESUMED)
    if resumed:
        parts.insert(0, resumed)
    return " | ".join(parts)


class StatusLine:
    """Draws ``source()`` (default: :func:`status_line` of the core ticked)."""

    def __init__(
        self,
        out: TextIO = sys.stderr,
        interval: float = 0.2,
        source: Callable[[], str] | None = None,
    ) -> None:
        self.out = out
        self.tty = out.isatty()
        self.interval = interval
        self.source = source
        self._last = ""
        self._drawn_at = 0.0
        self._host: Host | None = None
        self.ledger: ResumingLedger | None = None

    def attach(self, host: Host) -> None:
        """Redraw after each tick (``frog-bt run`` also refreshes it while nothing ticks)."""
        self._host = host
        self.ledger = ResumingLedger(host.site.tour_plan())
        self.ledger.attach(host)

    def on_event(self, event: Event) -> None:
        if self.ledger is not None:
            self.ledger.on_event(event)
        if isinstance(event, Ticked) and self._host is not None:
            self.update(self._host.core)

    def update(self, core: Core | None = None) -> None:
        now = time.monotonic()
        if self.tty and now - self._drawn_at < self.interval:
            return
        if self.source is not None:
            line = self.source()
        elif core is not None:
            line = status_line(core, self.ledger)
        else:
            return
        if line == self._last:
            return
        self._last, self._drawn_at = line, now
        if self.tty:
            self.out.write("\r\x1b[2K" + line[:200])
        else:
            self.out.write(line + "\n")
        self.out.flush()

    def close(self) -> None:
        if self.tty and self._last:
            self.out.write("\n")
            self.out.flush()
