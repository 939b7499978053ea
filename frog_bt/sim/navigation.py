"""Straight-line navigation of the simulated robot, stepped by ``dt``.

The robot drives towards a ``/GotoWayPoint`` goal in a straight line at the
scenario's speed, facing where it drives, and takes the goal's orientation on
arrival (within :data:`ARRIVAL_RADIUS`). A new goal replaces the active one.
Scenario ``navigation.failures`` rules turn chosen goals into a 3 (failed) or 4
(aborted) after some seconds of driving; the robot then stops where it is.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

from frog_bt.model.wire import ABORTED, FAILED, SUCCEEDED
from frog_bt.sim.scenario import NavFailure, NavigationSpec
from frog_bt.sim.site import poi_matches

log = logging.getLogger(__name__)
ARRIVAL_RADIUS = 0.05  # metres


@dataclass(slots=True)
class RobotPose:
    """Robot pose in the map frame; ``yaw`` in radians."""

    x: float
    y: float
    yaw: float = 0.0
    exact: tuple[float, float] | None = None  # (z, w) as given by a goal or the POI table

    @classmethod
    def from_quaternion(cls, x: float, y: float, qz: float, qw: float) -> RobotPose:
        pose = cls(x, y)
        pose.orient(qz, qw)
        return pose

    def orient(self, qz: float, qw: float) -> None:
        """Take a goal's orientation (reported back exactly as given)."""
        self.yaw, self.exact = 2.0 * math.atan2(qz, qw), (qz, qw)

    def turn(self, yaw: float) -> None:
        self.yaw, self.exact = yaw, None

    @property
    def quaternion(self) -> tuple[float, float]:
        """(z, w) of the yaw-only orientation quaternion."""
        if self.exact is not None:
            return self.exact
        return math.sin(self.yaw / 2.0), math.cos(self.yaw / 2.0)

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(x - self.x, y - self.y)


def drive(
    x: float, y: float, gx: float, gy: float, speed: float, dt: float
) -> tuple[float, float, bool]:
    """Position after driving ``dt`` seconds towards (gx, gy), and whether it has arrived."""
    dist = math.hypot(gx - x, gy - y)
    step = speed * dt
    if dist - step <= ARRIVAL_RADIUS:
        return gx, gy, True
    return x + (gx - x) * step / dist, y + (gy - y) * step / dist, False


@dataclass(slots=True)
class Goal:
    """An accepted ``/GotoWayPoint``: where, which POIs it is at, and its scripted fate."""

    number: int  # 1 for the first goal of the run
    x: float
    y: float
    qz: float
    qw: float
    pois: frozenset[str]
    fail_code: int | None = None  # FAILED or ABORTED when a scenario rule picked this goal
    fail_after: float = 0.0  # seconds of driving before failing
    driven: float = 0.0  # seconds driven so far


class Navigator:
    """Goal bookkeeping and the drive step; owns no pose (the world's pose is passed in)."""

    def __init__(self, spec: NavigationSpec) -> None:
        self.spec = spec
        self.goals = 0
        self.active: Goal | None = None
        self._used: dict[int, int] = {}  # failure rule index -> goals it has failed

    def new_goal(self, x: float, y: float, qz: float, qw: float, pois: frozenset[str]) -> Goal:
        """Accept a goal (replacing any active one) and decide whether a rule fails it."""
        self.goals += 1
        goal = Goal(self.goals, x, y, qz, qw, pois)
        for i, rule in enumerate(self.spec.failures):
            if self._picks(i, rule, goal):
                self._used[i] = self._used.get(i, 0) + 1
                goal.fail_code = FAILED if rule.result == "failed" else ABORTED
                goal.fail_after = rule.after
                log.info(
                    "goal %d (%s) will end %d after %.1f s by scenario",
                    goal.number,
                    ",".join(sorted(pois)) or "no POI",
                    goal.fail_code,
                    rule.after,
                )
                break
        self.active = goal
        return goal

    def _picks(self, index: int, rule: NavFailure, goal: Goal) -> bool:
        if rule.goal is not None:
            return rule.goal == goal.number
        assert rule.poi is not None
        return poi_matches(rule.poi, goal.pois) and self._used.get(index, 0) < rule.times

    def cancel(self) -> None:
        self.active = None

    def step(self, pose: RobotPose, dt: float) -> int | None:
        """Drive the active goal for ``dt``; the response code when the goal ends, else None."""
        goal = self.active
        if goal is None:
            return None
        goal.driven += dt
        if goal.fail_code is not None and goal.driven + 1e-9 >= goal.fail_after:
            self.active = None
            return goal.fail_code
        heading = math.atan2(goal.y - pose.y, goal.x - pose.x)
        pose.x, pose.y, arrived = drive(pose.x, pose.y, goal.x, goal.y, self.spec.speed, dt)
        if arrived:
            pose.orient(goal.qz, goal.qw)
            self.active = None
            return SUCCEEDED
        pose.turn(heading)
        return None
