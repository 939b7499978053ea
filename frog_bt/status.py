"""The live one-line status: phase, POI, tree tip, visitor, battery.

On a terminal the line is redrawn in place (at most every ``interval`` wall
seconds); elsewhere a line is printed only when it changes.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

import py_trees

from frog_bt.core import Core


def phase(core: Core) -> str:
    """The running child of the first sequence on the running path: the tour's phase."""
    node = core.bt.root
    running = py_trees.common.Status.RUNNING
    while True:
        if isinstance(node, py_trees.decorators.Decorator):
            node = node.decorated
            continue
        child = next((c for c in getattr(node, "children", ()) if c.status == running), None)
        if child is None:
            return node.status.value.lower()
        if isinstance(node, py_trees.composites.Sequence):
            return child.name
        node = child


def status_line(core: Core) -> str:
    storage = py_trees.blackboard.Blackboard.storage
    tip = core.bt.root.tip()
    diagnostics = storage.get("/diagnostics")
    battery = diagnostics.value.battery if diagnostics is not None else None
    parts = [
        phase(core),
        f"poi {storage.get('/waypoint') or '-'}",
        f"tip {tip.name if tip else '-'}",
        f"visitor {storage.get('/visitor') if storage.get('/visitor') is not None else '-'}",
        f"battery {battery:.0f}%" if battery is not None else "battery -",
    ]
    return " | ".join(parts)


class StatusLine:
    def __init__(self, out: TextIO = sys.stderr, interval: float = 0.2) -> None:
        self.out = out
        self.tty = out.isatty()
        self.interval = interval
        self._last = ""
        self._drawn_at = 0.0

    def update(self, core: Core) -> None:
        now = time.monotonic()
        if self.tty and now - self._drawn_at < self.interval:
            return
        line = status_line(core)
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
