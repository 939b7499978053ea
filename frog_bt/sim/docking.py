"""The docking station process, stepped by ``dt``.

``undock``: ``undocking`` then, after ``undock_time``, ``undocked``.
``dock``: ``docking`` then, after ``dock_time``, ``docked``; docking farther
than ``dock_range`` from the dock ends ``failed``. The first
``undock_failures`` / ``dock_failures`` attempts end ``failed`` on purpose.
A command for the state the robot is already in is answered with that state.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from frog_bt.sim.scenario import DockingSpec

log = logging.getLogger(__name__)


@dataclass(slots=True)
class _Process:
    command: str  # "dock" or "undock"
    remaining: float  # seconds
    fails: bool


class Docking:
    """Docking state machine; ``docked`` is whether the robot is held by the dock."""

    def __init__(self, spec: DockingSpec, docked: bool) -> None:
        self.spec = spec
        self.state = "docked" if docked else "undocked"
        self.docked = docked
        self._process: _Process | None = None
        self._attempts = {"dock": 0, "undock": 0}

    @property
    def busy(self) -> bool:
        return self._process is not None

    def command(self, command: str, near_dock: bool) -> str | None:
        """Start ``dock`` or ``undock``; the state to publish now (None for an unknown command)."""
        if command not in ("dock", "undock"):
            log.warning("unknown docking command %r ignored", command)
            return None
        target = "docked" if command == "dock" else "undocked"
        if self._process is None and self.state == target:
            return self.state
        self._attempts[command] += 1
        allowed = self.spec.dock_failures if command == "dock" else self.spec.undock_failures
        fails = self._attempts[command] <= allowed
        if command == "dock" and not near_dock and not self.docked:
            log.info(
                "dock requested %.1f m or more from the dock: it will fail", self.spec.dock_range
            )
            fails = True
        duration = self.spec.dock_time if command == "dock" else self.spec.undock_time
        self._process = _Process(command, duration, fails)
        self.state = "docking" if command == "dock" else "undocking"
        return self.state

    def put(self, docked: bool) -> str:
        """A person puts the robot on its charger (``docked``) or moves it off: any
        process stops; the state to publish now."""
        self._process = None
        self.docked = docked
        self.state = "docked" if docked else "undocked"
        return self.state

    def step(self, dt: float) -> str | None:
        """Advance the running process; the new state when it finishes, else None."""
        process = self._process
        if process is None:
            return None
        process.remaining -= dt
        if process.remaining > 1e-9:
            return None
        self._process = None
        if process.fails:
            # a failed undock leaves the robot on the dock; a failed dock leaves it off
            self.state = "failed"
            return self.state
        self.docked = process.command == "dock"
        self.state = "docked" if self.docked else "undocked"
        return self.state
