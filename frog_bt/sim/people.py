"""Scripted visitors: where they are, what the sensors see, how they react.

A visitor goes through these states::

    hidden ──appear_at──> present ──approach succeeded──> with_robot
                                                              │ user_positive / tour started
                                                              v
    gone <──after a while── leaving <──wander_off / no / tour over── following

* ``present``: stands where the scenario put them, with their scripted
  orientation relative to the robot (180 = facing it).
* ``with_robot``: approached successfully; the current visitor; faces the robot.
* ``following``: stays :data:`FOLLOW_DISTANCE` behind the robot while it drives.
* ``leaving``: walks away from the robot at :data:`WALK_SPEED` for
  :data:`LEAVE_SECONDS`, then is gone.

A visitor who answers no leaves. When a tour ends (front end ``tour`` ended or
aborted) the current visitor follows ``after_tour``: ``leave``, ``stay``
(stands where they are), or ``return`` (leaves, and a new visitor just like the
original appears at the original spot, with id + 1000 per return).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

from frog_bt.model.ros import Face, PersonDetection, Point, TrackedPerson
from frog_bt.sim.faces import EngagementScript
from frog_bt.sim.navigation import RobotPose
from frog_bt.sim.scenario import VisitorSpec
from frog_bt.sim.site import poi_matches

log = logging.getLogger(__name__)

FOLLOW_DISTANCE = 1.2  # metres behind the robot
APPROACH_DISTANCE = 1.0  # metres in front of the visitor after an approach
WALK_SPEED = 1.0  # m/s
LEAVE_SECONDS = 20.0
RETURN_ID_STEP = 1000

HIDDEN, PRESENT, WITH_ROBOT, FOLLOWING, LEAVING, GONE = (
    "hidden",
    "present",
    "with_robot",
    "following",
    "leaving",
    "gone",
)
VISIBLE = (PRESENT, WITH_ROBOT, FOLLOWING, LEAVING)


@dataclass(slots=True)
class Visitor:
    """One scripted person; ``x, y`` in the map frame."""

    spec: VisitorSpec
    id: int
    x: float
    y: float
    state: str
    orientation: float  # degrees relative to the robot, 180 = facing it
    approach_results: list[str]
    faces: EngagementScript
    generation: int = 0
    wandered: bool = False
    leave_left: float = 0.0
    _heading: tuple[float, float] = field(default=(1.0, 0.0))

    @property
    def visible(self) -> bool:
        return self.state in VISIBLE

    def leave(self, robot: RobotPose) -> None:
        """Turn away from the robot and walk off."""
        dx, dy = self.x - robot.x, self.y - robot.y
        norm = math.hypot(dx, dy)
        self._heading = (dx / norm, dy / norm) if norm > 1e-6 else (1.0, 0.0)
        self.state, self.orientation, self.leave_left = LEAVING, 0.0, LEAVE_SECONDS

    def walk(self, dt: float) -> None:
        self.x += self._heading[0] * WALK_SPEED * dt
        self.y += self._heading[1] * WALK_SPEED * dt
        self.leave_left -= dt
        if self.leave_left <= 0:
            self.state = GONE


class Crowd:
    """All visitors, and which one is the current visitor (the one approached)."""

    def __init__(
        self, specs: Iterable[VisitorSpec], seed: int = 0, detection_range: float = 15.0
    ) -> None:
        self.seed = seed
        self.detection_range = detection_range
        self.visitors: dict[int, Visitor] = {}
        self.current: int | None = None
        for spec in specs:
            self._spawn(spec, 0)

    def _spawn(self, spec: VisitorSpec, generation: int) -> Visitor:
        vid = spec.id + RETURN_ID_STEP * generation
        appears_now = spec.appear_at is not None and spec.appear_at <= 0
        state = PRESENT if generation or appears_now else HIDDEN
        visitor = Visitor(
            spec,
            vid,
            spec.position.x,
            spec.position.y,
            state,
            spec.detected_orientation,
            [] if isinstance(spec.approach, str) else list(spec.approach),
            EngagementScript(spec.faces, vid, self.seed),
            generation,
        )
        self.visitors[vid] = visitor
        return visitor

    @property
    def current_visitor(self) -> Visitor | None:
        return None if self.current is None else self.visitors.get(self.current)

    # ------------------------------------------------------------ time

    def step(
        self, elapsed: float, dt: float, robot: RobotPose, moved: tuple[float, float] = (0.0, 0.0)
    ) -> None:
        """Appear, follow, wander off at a time, walk away; ``elapsed`` since the start.

        ``moved`` is how far the robot drove this step (x, y): followers keep
        behind it along that direction.
        """
        travelled = math.hypot(*moved)
        for v in list(self.visitors.values()):
            if (
                v.state == HIDDEN
                and v.spec.appear_at is not None
                and v.generation == 0
                and elapsed + 1e-9 >= v.spec.appear_at
            ):
                v.state = PRESENT
                log.info("visitor %d appears at (%.1f, %.1f)", v.id, v.x, v.y)
            wander = v.spec.wander_off
            if (
                wander is not None
                and wander.at is not None
                and not v.wandered
                and elapsed + 1e-9 >= wander.at
                and v.state in (PRESENT, WITH_ROBOT, FOLLOWING)
            ):
                self._wander(v, robot)
            if v.state == FOLLOWING and travelled > 1e-9:
                v.x = robot.x - FOLLOW_DISTANCE * moved[0] / travelled
                v.y = robot.y - FOLLOW_DISTANCE * moved[1] / travelled
            elif v.state == LEAVING:
                v.walk(dt)

    def _wander(self, v: Visitor, robot: RobotPose) -> None:
        log.info("visitor %d wanders off", v.id)
        v.wandered = True
        v.leave(robot)

    # ------------------------------------------------------------ sensors

    def _in_range(self, robot: RobotPose) -> list[Visitor]:
        return [
            v
            for v in self.visitors.values()
            if v.visible and robot.distance_to(v.x, v.y) <= self.detection_range
        ]

    def detections(self, robot: RobotPose) -> list[PersonDetection]:
        """What the camera sees (``/UvA_PersonDetectionAndPose``)."""
        return [
            PersonDetection(v.id, Point(v.x, v.y, 0.0), v.orientation)
            for v in self._in_range(robot)
        ]

    def tracked(self, robot: RobotPose) -> list[TrackedPerson]:
        """What the laser tracks (``/PeopleUPO``)."""
        return [TrackedPerson(v.id, Point(v.x, v.y, 0.0)) for v in self._in_range(robot)]

    def faces(self) -> list[Face]:
        """One face sample of the current visitor while they are with the robot."""
        v = self.current_visitor
        if v is None or v.state not in (WITH_ROBOT, FOLLOWING):
            return []
        return [v.faces.sample()]

    # ------------------------------------------------------------ events

    def approach_outcome(self, vid: int, robot: RobotPose) -> str | None:
        """Scripted result of approaching ``vid`` (None: no such person in view)."""
        v = self.visitors.get(vid)
        if (
            v is None
            or v.state not in (PRESENT, WITH_ROBOT, FOLLOWING)
            or robot.distance_to(v.x, v.y) > self.detection_range
        ):
            return None
        if isinstance(v.spec.approach, str):
            return v.spec.approach
        return v.approach_results.pop(0) if v.approach_results else "succeeded"

    def approached(self, vid: int, robot: RobotPose) -> None:
        """A successful approach: the robot stands 1 m in front of ``vid``, facing them."""
        v = self.visitors.get(vid)
        if v is None or not v.visible:
            return
        dx, dy = robot.x - v.x, robot.y - v.y
        norm = math.hypot(dx, dy)
        ux, uy = (dx / norm, dy / norm) if norm > 1e-6 else (1.0, 0.0)
        robot.x, robot.y = v.x + APPROACH_DISTANCE * ux, v.y + APPROACH_DISTANCE * uy
        robot.turn(math.atan2(-uy, -ux))
        v.state, v.orientation = WITH_ROBOT, 180.0
        self.current = vid

    def answered(self, positive: bool, robot: RobotPose) -> None:
        """The current visitor answered the tour question."""
        v = self.current_visitor
        if v is None:
            return
        if positive:
            self.tour_started()
        else:
            v.leave(robot)
            self.current = None

    def tour_started(self) -> None:
        v = self.current_visitor
        if v is not None and v.state == WITH_ROBOT:
            v.state = FOLLOWING if v.spec.follow else PRESENT

    def heading_to(self, pois: frozenset[str], robot: RobotPose) -> None:
        """The robot was sent to ``pois``: visitors scripted to wander off then do."""
        for v in self.visitors.values():
            wander = v.spec.wander_off
            if (
                wander is not None
                and wander.heading_to is not None
                and not v.wandered
                and v.state in (WITH_ROBOT, FOLLOWING)
                and poi_matches(wander.heading_to, pois)
            ):
                self._wander(v, robot)

    def tour_over(self, robot: RobotPose) -> None:
        """The tour ended or was aborted: the current visitor does ``after_tour``."""
        v = self.current_visitor
        self.current = None
        if v is None:
            return
        if v.spec.after_tour == "stay":
            if v.state in (WITH_ROBOT, FOLLOWING):
                v.state = PRESENT
            return
        if v.state in (PRESENT, WITH_ROBOT, FOLLOWING):
            v.leave(robot)
        if v.spec.after_tour == "return":
            fresh = self._spawn(v.spec, v.generation + 1)
            log.info("visitor %d returns as visitor %d", v.id, fresh.id)
