"""Goals sent to the robot (a waypoint to drive to, a person to approach) and their answers."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from frog_bt.model.ros import Pose
from frog_bt.model.wire import Response

__all__ = ["Goal", "GoalKind"]

GoalKind = Literal["goto", "approach"]  # also the output role it is published on


@dataclass(frozen=True, slots=True)
class Goal:
    """A goal or approach sent to the robot, and its latest response (None: none yet)."""

    id: int
    kind: GoalKind
    target: str
    sent_at: float
    value: Pose | int  # as published, for a re-send
    code: Response | None = None
    answered_at: float | None = None
    poses: int = 0  # /FROG_pose messages received when it went out (believe: order)
    acknowledged: bool = False  # the robot said ``active`` after it went out

    @property
    def done(self) -> bool:
        return self.code is not None and self.code.terminal

    def state(self) -> str:
        """``sent``, or the latest response's word (``active``, ``succeeded``, ...)."""
        return "sent" if self.code is None else self.code.word
