"""Docking at and undocking from the charger (``/docking/dock``, ``/docking/state``)."""

from __future__ import annotations

import logging
import math
from typing import Literal

from pydantic import Field

from frog_bt.behaviours.goal_leaf import Failure, GoalLeaf
from frog_bt.behaviours.registry import register
from frog_bt.model import keys
from frog_bt.model.outcomes import DockingState, IncidentKind
from frog_bt.tree import leaf
from frog_bt.tree.leaf import RUNNING, SUCCESS, Status
from frog_bt.tree.world import Channel, World

TARGET = {"dock": DockingState.DOCKED, "undock": DockingState.UNDOCKED}
BUSY = {"dock": DockingState.DOCKING, "undock": DockingState.UNDOCKING}
log = logging.getLogger(__name__)
FAILED_GRACE = 2.0  # seconds after the command from which a "failed" is surely about it


@register
class Docking(GoalLeaf):
    """Dock or undock and wait for the robot to report it done.

    Reads ``/docking``, ``/now`` and ``/pose`` (optional). Sends ``/docking/dock``
    ``action`` in initialise (not when the robot already reports the target state);
    ``dock`` only at the dock's waypoint (``/pose`` within ``navigation.tolerance`` of
    site ``tour.dock``): asked anywhere else, or with no pose, it fails at once with
    that reason and sends nothing, so that the tree drives home again. SUCCESS
    on ``docked`` / ``undocked`` received after the command; FAILURE on
    ``failed`` once the robot has shown it took this command (``docking`` /
    ``undocking`` seen, or :data:`FAILED_GRACE` seconds passed: a ``failed`` left
    over from the previous attempt, re-published, must not fail this one), or
    after ``timeout`` seconds (default: site ``timeouts.dock`` / ``timeouts.undock``).
    """

    class Params(leaf.Params):  # qualified: mypy may take a bare Params for this one
        action: Literal["dock", "undock"] = Field(description="what to ask of the robot")
        timeout: float | None = Field(
            None,
            gt=0,
            allow_inf_nan=False,
            description=("seconds before it fails (default: site timeouts.dock / timeouts.undock)"),
        )

    params: Params
    reads = (keys.DOCKING, keys.NOW)
    optional_reads = (keys.POSE,)
    world = World(
        inputs=(Channel.DOCKING, Channel.POSE, Channel.CLOCK),
        state=(*GoalLeaf.world.state, "already", "took", "away"),
        times=GoalLeaf.world.times,
        timer=GoalLeaf.world.timer,
        docking=lambda n: (
            (TARGET[n.params.action].value, DockingState.FAILED.value)
            if n.sent_at is not None and not n.already and n.away is None
            else ()
        ),
        places=lambda n: (n.ctx.site.tour.dock,) if n.params.action == "dock" else (),
        why="the robot reports the state asked for, or failed, at the next tick",
    )

    def default_timeout(self) -> float:
        timeouts = self.ctx.site.timeouts
        return float(getattr(timeouts, self.params.action))

    def begin(self) -> None:
        state = self.get(keys.DOCKING)
        self.already = state is not None and state.value == TARGET[self.params.action]
        self.took = False
        self.away = None if self.already or self.params.action != "dock" else self._away()

    def _away(self) -> str | None:
        """Why the robot is not at the dock's waypoint (None: it is)."""
        site = self.ctx.site
        dock = site.tour.dock
        reading = self.get(keys.POSE)
        if reading is None:
            return f"no pose: the robot may not be at {dock}"
        here, there = reading.value, site.pois[dock]
        away = math.hypot(here.x - there.x, here.y - there.y)
        tolerance = site.navigation.tolerance
        return f"the robot is {away:.0f} m from {dock}" if away > tolerance else None

    def send(self) -> None:
        if self.away is not None:
            log.warning("dock not sent: %s", self.away)
            self.ctx.note(f"dock not sent: {self.away}")
        elif not self.already:
            self.ctx.actions.dock(self.params.action)
            self.ctx.note(f"{self.params.action}")

    def poll(self) -> Status | Failure:
        if self.away is not None:
            return Failure.AWAY
        if self.already:
            return SUCCESS
        assert self.sent_at is not None
        state = self.get(keys.DOCKING)
        if state is not None and state.at >= self.sent_at:
            if state.value == TARGET[self.params.action]:
                return SUCCESS
            if state.value == BUSY[self.params.action]:
                self.took = True
            if state.value == DockingState.FAILED and (
                self.took or state.at - self.sent_at >= FAILED_GRACE
            ):
                return Failure.REFUSED
        return RUNNING

    def failed(self, why: Failure) -> None:
        if why is Failure.AWAY:
            self.feedback_message = f"not at the dock: {self.away}"
            return  # noted as it was not sent; nothing failed at the dock
        action = self.params.action
        self.ctx.note(
            f"{action}: no {TARGET[action]} within {self.timeout:g} s"
            if why is Failure.TIMED_OUT
            else f"{action} failed",
            incident=IncidentKind.DOCKING_FAILED,
        )

    def progress(self) -> str:
        state = self.get(keys.DOCKING)
        return f"{state.value if state else 'no state'}"
