"""Believe a robot's answer only when it fits what else the robot says.

``/FROG_response`` carries no goal id (CONTRACT §1): a code is the answer to "the latest
goal". But an answer may be on its way when the executive sends the next goal — a
stop's "arrived" just after a fault sent the robot home — and taken as the new goal's
answer it docks the robot 70 m from its charger. Nav2's ``BtActionNode`` drops a result
whose goal id is not its own; with no id on the wire, the same rule is built from what
the robot also says (STYLE: "Believe only what fits"):

* **order** — a goal sent while another was still open (no final answer yet) may meet
  that one's answer first. Until the robot shows it took the new goal (an ``active``
  for it, or a ``/FROG_pose`` that arrived after it went out), a final answer is
  *stale*: it answers the goal before, and is never acted on;
* **the world** — "arrived" is believed only when the latest pose is within
  ``navigation.tolerance`` metres of the goal; an approach's success only while the
  visitor is still seen (camera detections fresher than ``recruit.detection_max_age``).
  An answer that does not fit is *doubted*: not acted on, and the goal waits on for the
  next answer or its own timeout; an arrival is still believed if a pose received after
  it, within ``navigation.pose_grace`` seconds, shows the robot there
  (:meth:`~frog_bt.engine.actions.Actions.confirm`: a robot may publish "arrived" just
  before its last pose).

:func:`judge` is pure: a goal, a code and what the robot said besides, in; a
:class:`Judgement` out. :class:`~frog_bt.engine.actions.Actions` applies it; every answer
not believed is told to the host (a :class:`~frog_bt.model.events.Doubted` event: logged
once, recorded, noted in the journal) and replay re-judges it identically.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from frog_bt.model.goals import Goal
from frog_bt.model.key import Reading
from frog_bt.model.ros import PersonDetections, Pose
from frog_bt.model.wire import ABORTED, ACTIVE, FAILED, SUCCEEDED

__all__ = ["Judgement", "Verdict", "World", "describe_answer", "judge"]


class Verdict(enum.Enum):
    BELIEVED = "believed"
    STALE = "stale"  # it answers an earlier goal (order)
    DOUBTED = "doubted"  # it does not fit what the robot says of the world


@dataclass(frozen=True, slots=True)
class Judgement:
    verdict: Verdict
    why: str = ""  # in domain terms, for the log, the recording and replay
    answers: str = ""  # the earlier goal it is taken to answer (its target), if known


@dataclass(frozen=True, slots=True)
class World:
    """What the robot said besides the answer, as the judge needs it."""

    now: float
    pose: Reading[Pose] | None  # the latest /FROG_pose
    persons: Reading[PersonDetections] | None  # the latest camera detections
    poses_at_answer: int  # /FROG_pose messages received before the answer arrived
    tolerance: float  # metres: navigation.tolerance
    detection_max_age: float  # seconds: recruit.detection_max_age


def goal_words(goal: Goal) -> str:
    """A goal as people say it: ``the drive to SHOP``, ``the approach of visitor 7``."""
    if goal.kind == "approach":
        return f"the approach of visitor {goal.target}"
    return f"the drive to {goal.target}"


def describe_answer(code: int, goal: Goal | None) -> str:
    """An answer as people say it, for the goal it answers: ``arrival at POI2``."""
    if goal is None:
        return f"/FROG_response {code}"
    if goal.kind == "approach":
        word: dict[int, str] = {
            SUCCEEDED: "success",
            FAILED: "failure",
            ABORTED: "refusal",
            ACTIVE: "start",
        }
        return f"{word.get(code, str(code))} of the approach of visitor {goal.target}"
    drive: dict[int, str] = {
        SUCCEEDED: "arrival at",
        FAILED: "failure of the drive to",
        ABORTED: "abort of the drive to",
    }
    return f"{drive.get(code, 'start of the drive to')} {goal.target}"


def distance(pose: Pose, goal: Goal) -> float:
    """Metres from ``pose`` to a drive's goal (0 for an approach: no fixed place)."""
    target = goal.value
    if not isinstance(target, Pose):
        return 0.0
    return math.hypot(pose.x - target.x, pose.y - target.y)


def judge(goal: Goal, code: int, world: World, before: Goal | None) -> Judgement:
    """Is ``code`` the answer to ``goal``? ``before`` is the goal it replaced while that
    one was still open (None when the one before had its final answer, or none was)."""
    if before is not None and not goal.acknowledged and world.poses_at_answer <= goal.poses:
        if code == ACTIVE:
            return Judgement(Verdict.BELIEVED)  # the robot took a goal: this one, or no harm
        return Judgement(
            Verdict.STALE,
            f"{describe_answer(code, before)} heard after {goal_words(goal)}: ignored",
            before.target,
        )
    if code != SUCCEEDED:
        return Judgement(Verdict.BELIEVED)
    if goal.kind == "goto":
        pose = world.pose
        if pose is None:
            return Judgement(
                Verdict.DOUBTED, f"arrival at {goal.target} heard with no pose yet: not believed"
            )
        away = distance(pose.value, goal)
        if away > world.tolerance:
            if before is not None and distance(pose.value, before) <= world.tolerance:
                return Judgement(
                    Verdict.STALE,
                    f"{describe_answer(code, before)} heard after {goal_words(goal)}: ignored",
                    before.target,
                )
            return Judgement(
                Verdict.DOUBTED,
                f"arrival at {goal.target} heard {away:.0f} m from it: not believed",
            )
        return Judgement(Verdict.BELIEVED)
    persons = world.persons
    seen = (
        persons is not None
        and persons.age(world.now) <= world.detection_max_age
        and any(str(p.id) == goal.target for p in persons.value.persons)
    )
    if not seen:
        return Judgement(
            Verdict.DOUBTED,
            f"approach of visitor {goal.target} succeeded, but they are not seen: not believed",
        )
    return Judgement(Verdict.BELIEVED)
