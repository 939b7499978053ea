"""The simulated robot and its surroundings, with no I/O and no clock of its own.

:class:`World` takes the messages the executive publishes
(:meth:`World.handle`) and is stepped by hand (:meth:`World.step`, explicit
``dt``); both return the ``(topic, msg)`` pairs the robot publishes in answer.
What it publishes, in simulated time:

* ``/FROG_pose`` at 10 Hz; ``/FROG_response`` 1 when a goal or approach is
  accepted, then 2, 3 or 4 when it ends (4 at once when it is refused: the
  robot is on the dock, or the person is not in view);
* ``/docking/state`` on every change and at 1 Hz;
* ``/UvA_PersonDetectionAndPose`` and ``/PeopleUPO`` at 5 Hz (people within
  ``detection_range``);
* ``/ICL_FaceDataStream`` at 10 Hz between ``/ICL_command`` start and stop;
* ``/diagnostic`` at 1 Hz (battery, scripted faults).

The front-end simulator tells the world what the visitor answered and when a
tour starts or ends (:meth:`World.on_frontend`), so that visitors follow the
robot and leave at the right moments.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import frog_bt.sim.msgs as msgs
from frog_bt.errors import ConfigError, DecodeError
from frog_bt.model import ros
from frog_bt.model.wire import ABORTED, ACTIVE, FAILED, INPUTS, OUTPUTS, SUCCEEDED
from frog_bt.sim.diagnostics import Battery, active_faults
from frog_bt.sim.docking import Docking
from frog_bt.sim.navigation import Navigator, RobotPose
from frog_bt.sim.people import Crowd, Visitor
from frog_bt.sim.scenario import Scenario
from frog_bt.sim.site import PoiPose, poi_matches, pois_at

log = logging.getLogger(__name__)

Out = tuple[str, dict[str, Any]]
POSE, RESPONSE, DOCKING_STATE, DIAGNOSTIC, PERSONS, FACES, PEOPLE = (
    INPUTS[k].name
    for k in ("pose", "response", "docking_state", "diagnostic", "persons", "faces", "people")
)
GOTO, APPROACH, ICL, DOCK = (OUTPUTS[k].name for k in ("goto", "approach", "icl", "dock"))
OUTCOME_CODES = {"succeeded": SUCCEEDED, "failed": FAILED, "aborted": ABORTED}


@dataclass(slots=True)
class Rate:
    """Due every ``period`` seconds of elapsed time (never more than once per step)."""

    period: float
    next: float = -1.0  # first due one period after the start

    def __post_init__(self) -> None:
        if self.next < 0:
            self.next = self.period

    def due(self, elapsed: float) -> bool:
        if elapsed + 1e-6 < self.next:
            return False
        self.next += self.period
        if self.next <= elapsed:
            self.next = elapsed + self.period
        return True


@dataclass(slots=True)
class Approach:
    """A running ``/ApproachPeopleFar``."""

    visitor: int
    remaining: float
    outcome: str


def check_pois(scenario: Scenario, pois: Mapping[str, PoiPose]) -> None:
    """Every POI a scenario names must be in the POI table (raises ConfigError)."""
    known = ", ".join(sorted(pois))
    where = scenario.name or "<scenario>"
    refs: list[tuple[tuple[str | int, ...], str]] = [(("robot", "start"), scenario.robot.start)]
    refs += [
        (("navigation", "failures", i, "poi"), f.poi)
        for i, f in enumerate(scenario.navigation.failures)
        if f.poi is not None
    ]
    refs += [
        (("navigation", "late", i, "poi"), late.poi)
        for i, late in enumerate(scenario.navigation.late)
        if late.poi is not None
    ]
    refs += [
        (("faults", i, "on_arrival"), f.on_arrival)
        for i, f in enumerate(scenario.faults)
        if f.on_arrival is not None
    ]
    refs += [
        (("visitors", i, "wander_off", "heading_to"), v.wander_off.heading_to)
        for i, v in enumerate(scenario.visitors)
        if v.wander_off is not None and v.wander_off.heading_to is not None
    ]
    for path, name in refs:
        if not poi_matches(name, pois):
            raise ConfigError(where, path, f"unknown POI {name!r} (known: {known})")


class World:
    """Robot, dock, battery and visitors of one scenario, at time ``now``."""

    def __init__(
        self, scenario: Scenario, pois: Mapping[str, PoiPose], start: float | None = None
    ) -> None:
        check_pois(scenario, pois)
        self.scenario = scenario
        self.pois = dict(pois)
        self.start = scenario.start_epoch if start is None else start
        self.elapsed = 0.0
        dock = self.pois[scenario.robot.start]
        self.dock_pose = RobotPose.from_quaternion(*dock)
        spec_pose = scenario.robot.pose
        self.pose = (
            RobotPose(spec_pose.x, spec_pose.y, math.radians(spec_pose.yaw))
            if spec_pose is not None
            else RobotPose.from_quaternion(*dock)
        )
        self.navigator = Navigator(scenario.navigation)
        self.docking = Docking(scenario.docking, scenario.robot.docked)
        self.battery = Battery(scenario.battery)
        self.crowd = Crowd(scenario.visitors, scenario.seed, scenario.detection_range)
        self.faces_on = False
        self.approach: Approach | None = None
        self.arrivals: dict[str, float] = {}  # scenario POI -> first arrival (on_arrival faults)
        self.fixed_at: float | None = None  # a person fixed the faults reported then
        self.late: list[tuple[float, Out]] = []  # answers held back: (due, what)
        self.malformed = 0
        self._rates = {
            POSE: Rate(0.1),
            PERSONS: Rate(0.2),
            PEOPLE: Rate(0.2),
            FACES: Rate(0.1),
            DIAGNOSTIC: Rate(1.0),
            DOCKING_STATE: Rate(1.0),
        }
        self._handlers: dict[str, Callable[[Any], list[Out]]] = {
            GOTO: self._on_goto,
            APPROACH: self._on_approach,
            ICL: self._on_icl,
            DOCK: self._on_dock,
        }

    # ------------------------------------------------------------ state

    @property
    def now(self) -> float:
        """Simulated time, seconds since the epoch."""
        return self.start + self.elapsed

    @property
    def docking_state(self) -> str:
        return self.docking.state

    @property
    def visitors(self) -> dict[int, Visitor]:
        return self.crowd.visitors

    @property
    def current_visitor(self) -> Visitor | None:
        return self.crowd.current_visitor

    @property
    def handled_topics(self) -> tuple[str, ...]:
        return tuple(self._handlers)

    # ------------------------------------------------------------ inputs

    def handle(self, topic: str, msg: Any) -> list[Out]:
        """A message the executive published; what the robot publishes at once in answer."""
        handler = self._handlers.get(topic)
        if handler is None:
            return []
        try:
            return handler(msg)
        except DecodeError as exc:
            self.malformed += 1
            log.warning("malformed %s ignored: %s", topic, exc)
            return []

    def _response(self, code: int) -> Out:
        return RESPONSE, ros.INT32.encode(code)

    def _held(self, what: str) -> bool:
        if self.docking.docked or self.docking.busy:
            log.warning("%s refused: the robot is %s", what, self.docking.state)
            return True
        return False

    def _on_goto(self, msg: Any) -> list[Out]:
        goal = ros.POSE.convert(msg)
        self.approach = None
        if self._held("goal"):
            self.navigator.cancel()
            return [self._response(ABORTED)]
        pois = pois_at(self.pois, goal.x, goal.y)
        self.navigator.new_goal(goal.x, goal.y, goal.qz, goal.qw, pois)
        log.info("goal to (%.2f, %.2f) %s", goal.x, goal.y, ",".join(sorted(pois)))
        self.crowd.heading_to(pois, self.pose)
        return self._answer(ACTIVE, pois)

    def _answer(self, code: int, pois: frozenset[str]) -> list[Out]:
        """A goal's answer now, or held back by a ``navigation.late`` rule (a newer goal
        does not cancel it: it may arrive after that goal went out)."""
        for rule in self.scenario.navigation.late:
            if rule.poi is None or poi_matches(rule.poi, pois):
                copies = 2 if rule.duplicate and code != ACTIVE else 1
                due = self.elapsed + rule.delay
                self.late.extend((due, self._response(code)) for _ in range(copies))
                return []
        return [self._response(code)]

    def _on_approach(self, msg: Any) -> list[Out]:
        vid = ros.INT32.convert(msg)
        self.navigator.cancel()
        self.approach = None
        if self._held("approach"):
            return [self._response(ABORTED)]
        outcome = self.crowd.approach_outcome(vid, self.pose)
        if outcome is None:
            log.info("approach to person %d refused: not in view", vid)
            return [self._response(ABORTED)]
        self.approach = Approach(vid, self.scenario.navigation.approach_time, outcome)
        return [self._response(ACTIVE)]

    def _on_icl(self, msg: Any) -> list[Out]:
        command = ros.STRING.convert(msg)
        if command in ("start", "stop"):
            self.faces_on = command == "start"
        else:
            log.warning("unknown ICL command %r ignored", command)
        return []

    def _on_dock(self, msg: Any) -> list[Out]:
        command = ros.STRING.convert(msg)
        near = (
            self.pose.distance_to(self.dock_pose.x, self.dock_pose.y)
            <= self.scenario.docking.dock_range
        )
        if command in ("dock", "undock"):
            self.navigator.cancel()
            self.approach = None
        state = self.docking.command(command, near)
        return [] if state is None else [(DOCKING_STATE, ros.STRING.encode(state))]

    def on_frontend(self, direction: str, channel: str, payload: Mapping[str, Any]) -> None:
        """Front-end traffic that matters to visitors: the answer, and tour start / end."""
        if direction == "out" and channel in ("user_positive", "user_negative"):
            self.crowd.answered(channel == "user_positive", self.pose)
        elif direction == "in" and channel == "tour":
            state = payload.get("state")
            if state == "started":
                self.crowd.tour_started()
            elif state in ("ended", "aborted"):
                self.crowd.tour_over(self.pose)

    # ------------------------------------------------------------ a person's hands

    def by_hand(self, about: str) -> None:
        """A person does the step the robot could not (``about``, as the executive's help
        names it): ``dock``, ``home`` and ``crashed`` put the robot on its charger,
        ``undock`` moves it off, ``fault`` fixes the faults reported now. What changed is
        published at the next step."""
        self.navigator.cancel()
        self.approach = None
        if about == "fault":
            self.fixed_at = self.elapsed
            self._rates[DIAGNOSTIC].next = self.elapsed
            return
        self.docking.put(about != "undock")
        if about != "undock":
            d = self.dock_pose
            self.pose = RobotPose(d.x, d.y, d.yaw, d.exact)
        self._rates[DOCKING_STATE].next = self.elapsed
        self._rates[POSE].next = self.elapsed

    # ------------------------------------------------------------ time

    def step(self, dt: float) -> list[Out]:
        """Advance the world by ``dt`` seconds; everything the robot publishes meanwhile."""
        self.elapsed += dt
        out: list[Out] = []
        before = (self.pose.x, self.pose.y)
        if not self.docking.docked:
            goal = self.navigator.active
            code = self.navigator.step(self.pose, dt)
            if code is not None and goal is not None:
                if code == SUCCEEDED:
                    self._arrived(goal.pois)
                out += self._answer(code, goal.pois)
        if self.late:
            due = [o for t, o in self.late if t <= self.elapsed + 1e-9]
            self.late = [(t, o) for t, o in self.late if t > self.elapsed + 1e-9]
            out += due
        out += self._step_approach(dt)
        state = self.docking.step(dt)
        if state is not None:
            if state == "docked":
                d = self.dock_pose
                self.pose = RobotPose(d.x, d.y, d.yaw, d.exact)
            out.append((DOCKING_STATE, ros.STRING.encode(state)))
        self.battery.step(dt, self.docking.docked)
        moved = (self.pose.x - before[0], self.pose.y - before[1])
        self.crowd.step(self.elapsed, dt, self.pose, moved)
        out += self._publications()
        return out

    def _arrived(self, pois: frozenset[str]) -> None:
        """Note the first arrival at each scenario POI a fault waits for; its fault is
        published at once (not at the next 1 Hz report)."""
        for fault in self.scenario.faults:
            name = fault.on_arrival
            if name is not None and name not in self.arrivals and poi_matches(name, pois):
                self.arrivals[name] = self.elapsed
                self._rates[DIAGNOSTIC].next = self.elapsed  # due now

    def _step_approach(self, dt: float) -> list[Out]:
        approach = self.approach
        if approach is None:
            return []
        approach.remaining -= dt
        if approach.remaining > 1e-9:
            return []
        self.approach = None
        if approach.outcome == "succeeded":
            self.crowd.approached(approach.visitor, self.pose)
        return [self._response(OUTCOME_CODES[approach.outcome])]

    def _publications(self) -> list[Out]:
        now, elapsed, rates = self.now, self.elapsed, self._rates
        out: list[Out] = []
        if rates[POSE].due(elapsed):
            qz, qw = self.pose.quaternion
            out.append((POSE, msgs.pose_stamped(self.pose.x, self.pose.y, qz, qw, now)))
        if rates[PERSONS].due(elapsed):
            out.append((PERSONS, msgs.person_detections(now, self.crowd.detections(self.pose))))
        if rates[PEOPLE].due(elapsed):
            out.append((PEOPLE, msgs.tracked_people(now, self.crowd.tracked(self.pose))))
        if self.faces_on and rates[FACES].due(elapsed):
            out.append((FACES, msgs.face_data(now, self.crowd.faces())))
        if rates[DIAGNOSTIC].due(elapsed):
            faults = active_faults(self.scenario.faults, elapsed, self.arrivals, self.fixed_at)
            statuses = [self.battery.status(), *faults]
            out.append((DIAGNOSTIC, msgs.diagnostic_array(now, statuses)))
        if rates[DOCKING_STATE].due(elapsed):
            out.append((DOCKING_STATE, ros.STRING.encode(self.docking.state)))
        return out
