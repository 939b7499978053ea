"""Docking at and undocking from the charger (``/docking/dock``, ``/docking/state``)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from frog_bt.behaviours.registry import register
from frog_bt.model import keys
from frog_bt.model.outcomes import IncidentKind
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status

TARGET = {"dock": "docked", "undock": "undocked"}
BUSY = {"dock": "docking", "undock": "undocking"}
FAILED_GRACE = 2.0  # seconds after the command from which a "failed" is surely about it


@register
class Docking(Leaf):
    """Dock or undock and wait for the robot to report it done.

    Reads ``/docking`` and ``/now``. Sends ``/docking/dock`` ``action`` in
    initialise (not when the robot already reports the target state). SUCCESS
    on ``docked`` / ``undocked`` received after the command; FAILURE on
    ``failed`` once the robot has shown it took this command (``docking`` /
    ``undocking`` seen, or :data:`FAILED_GRACE` seconds passed: a ``failed`` left
    over from the previous attempt, re-published, must not fail this one), or
    after ``timeout`` seconds (default: site ``timeouts.dock`` / ``timeouts.undock``).
    """

    class Params(Params):
        action: Literal["dock", "undock"] = Field(description="what to ask of the robot")
        timeout: float | None = Field(None, gt=0, allow_inf_nan=False, description=(
            "seconds before it fails (default: site timeouts.dock / timeouts.undock)"))

    reads = (keys.DOCKING, keys.NOW)

    def initialise(self) -> None:
        action = self.params.action
        state = self.get(keys.DOCKING)
        self.sent_at = self.ctx.clock.now()
        self.already = state is not None and state.value == TARGET[action]
        self.took = False
        if not self.already:
            self.ctx.actions.dock(action)
            self.ctx.note(f"{action}")
        timeouts = self.ctx.site.timeouts
        self.timeout = self.params.timeout or getattr(timeouts, action)

    def update(self) -> Status:
        if self.already:
            return SUCCESS
        state = self.get(keys.DOCKING)
        if state is not None and state.at >= self.sent_at:
            if state.value == TARGET[self.params.action]:
                return SUCCESS
            if state.value == BUSY[self.params.action]:
                self.took = True
            if state.value == "failed" and (
                    self.took or state.at - self.sent_at >= FAILED_GRACE):
                self.ctx.note(f"{self.params.action} failed", incident=IncidentKind.DOCKING_FAILED)
                return FAILURE
        if self.need(keys.NOW) - self.sent_at >= self.timeout:
            self.ctx.note(f"{self.params.action}: no {TARGET[self.params.action]} "
                          f"within {self.timeout:g} s", incident=IncidentKind.DOCKING_FAILED)
            return FAILURE
        self.feedback_message = f"{state.value if state else 'no state'}"
        return RUNNING
