"""What outlives a tree: the state people and the executive set, owned by the executive.

A reload (``--watch``) builds a new :class:`~frog_bt.engine.core.Core` for the new tree;
each core gets the executive's one :class:`Standing` injected, so nothing people decided
is lost with the old tree: in service or not, a pause and its timer, the resume point,
the front end's events and readiness, the tours' state, the decision journal with its
incidents and their tally, the robot's latest inputs, and the run's id (what its
recordings carry, :mod:`frog_bt.model.run`).
"""

from __future__ import annotations

from typing import Any

from frog_bt.clock import Clock
from frog_bt.engine.blackboard import Inputs
from frog_bt.engine.faults import Faults
from frog_bt.engine.journal import Journal
from frog_bt.model.key import Key
from frog_bt.model.run import RunId

__all__ = ["Standing"]


class Standing:
    """The executive's own state, shared by every core it builds."""

    def __init__(self, clock: Clock) -> None:
        self.values: dict[Key[Any], Any] = {}  # the lasting keys (Board routes them here)
        self.paused_since: float | None = None  # the operator's pause, on the project clock
        self.journal = Journal(clock)
        self.faults = Faults(clock)  # the executive's own failures, caught and counted
        self.inputs: Inputs | None = None  # the robot's latest inputs (the first core's)
        self.run = RunId.new()  # a resumed executive's: the run its checkpoint names
