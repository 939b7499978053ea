"""Finding, approaching and introducing a visitor at POI0 (seed: "POI0")."""

from __future__ import annotations

import math

from pydantic import Field

from frog_bt.behaviours.goal_leaf import Failure, GoalLeaf
from frog_bt.behaviours.registry import register
from frog_bt.engine.observed import Role
from frog_bt.model import keys
from frog_bt.model.frontend import AskTour as AskTourCommand
from frog_bt.model.frontend import StartIntroduction as StartIntroductionCommand
from frog_bt.model.frontend import UserNegative, UserPositive
from frog_bt.model.goals import Goal
from frog_bt.model.outcomes import IncidentKind
from frog_bt.model.ros import PersonDetection, Pose
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status
from frog_bt.tree.world import Channel, World
from frog_bt.tree.world import Role as WorldRole

Timeout = Field(
    None,
    gt=0,
    allow_inf_nan=False,
    description="seconds before it fails (default: the site's timeouts entry)",
)


def facing_visitor(
    persons: tuple[PersonDetection, ...],
    pose: Pose,
    lo: float,
    hi: float,
    exclude: frozenset[int] = frozenset(),
) -> PersonDetection | None:
    """The nearest person facing the robot (``lo < orientation < hi``), not in ``exclude``."""
    candidates = [p for p in persons if lo < p.orientation < hi and p.id not in exclude]
    if not candidates:
        return None
    return min(
        candidates, key=lambda p: (math.hypot(p.position.x - pose.x, p.position.y - pose.y), p.id)
    )


def cooling_down(failed: dict[int, float] | None, now: float, retry_after: float) -> frozenset[int]:
    """People whose approach failed less than ``retry_after`` seconds before ``now``."""
    if not failed:
        return frozenset()
    return frozenset(pid for pid, at in failed.items() if now - at < retry_after)


@register
class SeekVisitor(Leaf):
    """Look for a visitor: a person facing the robot, the nearest when several.

    Reads ``/persons`` (ignored when older than site ``recruit.detection_max_age``),
    ``/pose``, ``/now``, ``/declined`` (people who said no this tour) and
    ``/approach_failed`` (person -> time their approach failed: passed over for
    ``recruit.retry_after`` seconds, so another facing visitor is tried first).
    Writes ``/visitor`` (the person id). RUNNING until someone qualifies, then SUCCESS.
    """

    role = Role.SEEK  # the executive's alert when the search runs too long
    reads = (keys.PERSONS, keys.POSE, keys.NOW)
    optional_reads = (keys.DECLINED, keys.APPROACH_FAILED)
    writes = (keys.VISITOR,)
    world = World(
        inputs=(Channel.VISITOR, Channel.POSE),
        waits=True,
        ignores=(keys.DECLINED.name, keys.APPROACH_FAILED.name),
        people=(keys.VISITOR.name,),
        sets=(keys.VISITOR.name,),
        why="nobody faces the robot, or someone it has not seen before: a person seen "
        "again is either passed over (declined, or their approach failed: as if nobody "
        "faced it) or, people being alike, one more new person; so whom it passes "
        "over changes none of its outcomes",
    )

    def update(self) -> Status:
        cfg = self.ctx.site.recruit
        persons = self.get(keys.PERSONS)
        pose = self.get(keys.POSE)
        now = self.need(keys.NOW)
        if pose is None:
            self.feedback_message = "no pose yet"
            return RUNNING
        if persons is None or persons.age(now) > cfg.detection_max_age:
            self.feedback_message = "no recent person detections"
            return RUNNING
        declined = self.get(keys.DECLINED) or frozenset()
        cooling = cooling_down(self.get(keys.APPROACH_FAILED), now, cfg.retry_after)
        person = facing_visitor(
            persons.value.persons, pose.value, cfg.facing_min, cfg.facing_max, declined | cooling
        )
        if person is None:
            seen = len(persons.value.persons)
            self.feedback_message = f"{seen} seen, none facing" + (
                f" but {', '.join(map(str, sorted(cooling)))} (approach failed)" if cooling else ""
            )
            return RUNNING
        self.set(keys.VISITOR, person.id)
        self.ctx.note(
            f"visitor {person.id} faces the robot "
            f"({person.orientation:.0f} deg), nearest of {len(persons.value.persons)}"
        )
        return SUCCESS


def _run_out(node: ApproachVisitor, seconds: float) -> None:
    """verify: its wait runs out now (the approach's timeout, or before it goes out, the
    interval since the previous approach)."""
    if node.sent_at is not None:
        node.sent_at -= seconds
    else:
        node.ctx.actions.last_approach_at -= seconds


@register
class ApproachVisitor(GoalLeaf):
    """Approach ``/visitor`` with ``/ApproachPeopleFar``, never faster than the site allows.

    Reads ``/visitor``, ``/now``, ``/goal`` (its result), ``/approach_failed``, ``/paused``
    and ``/pose``; writes ``/approach_failed``.
    The command goes out once ``recruit.approach_interval`` seconds have passed
    since the previous approach, and not while the operator's pause lasts (RUNNING
    until then; a pause while it is out stops the robot where it is, and the approach
    goes out again after ``resume``). SUCCESS on
    ``/FROG_response`` 2; FAILURE on 3 or 4, or after ``timeout`` (default: site
    ``timeouts.approach``), recording the person in ``/approach_failed`` so that
    the next search passes them over for ``recruit.retry_after`` seconds.
    """

    class Params(Params):
        timeout: float | None = Timeout

    params: Params
    reads = (keys.VISITOR, keys.NOW, keys.GOAL)
    optional_reads = (keys.APPROACH_FAILED, keys.PAUSED, keys.POSE)
    writes = (keys.APPROACH_FAILED,)
    waits_while_paused = True
    world = World(
        inputs=(Channel.GOAL, Channel.VISITOR, Channel.OPERATOR, Channel.CLOCK),
        state=(*GoalLeaf.world.state, "visitor"),
        times=GoalLeaf.world.times,
        timer=lambda n: (
            n.sent_at + n.timeout
            if n.sent_at is not None
            else n.ctx.actions.last_approach_at + n.ctx.site.recruit.approach_interval
        ),
        fire=lambda n, seconds: _run_out(n, seconds),
        active="sent_at",
        role=WorldRole.APPROACH,
        ignores=(keys.APPROACH_FAILED.name,),
        people=("visitor",),
        why="the robot reaches the visitor (while the camera sees them) or fails at the "
        "next tick; the next approach waits recruit.approach_interval. It reads "
        "/approach_failed only to add to it",
    )

    def default_timeout(self) -> float:
        return self.ctx.site.timeouts.approach

    def begin(self) -> None:
        visitor = self.get(keys.VISITOR)
        assert visitor is not None  # a required read of a leaf's key: never None
        self.visitor = visitor

    def hold(self) -> str | None:
        due = self.ctx.actions.last_approach_at + self.ctx.site.recruit.approach_interval
        now = self.ctx.clock.now()
        return f"next approach in {due - now:.1f} s" if now < due else None

    def send(self) -> Goal:
        goal = self.ctx.actions.approach(self.visitor)
        self.ctx.note(f"approach visitor {self.visitor}")
        return goal

    def succeeded(self) -> None:
        self.ctx.note(f"approached visitor {self.visitor}")

    def failed(self, why: Failure) -> None:
        how = self.latest.state() if why is Failure.REFUSED and self.latest else why.value
        failed = dict(self.get(keys.APPROACH_FAILED) or {})
        now = self.need(keys.NOW)
        retry_after = self.ctx.site.recruit.retry_after
        failed = {pid: at for pid, at in failed.items() if now - at < retry_after}
        failed[self.visitor] = now
        self.set(keys.APPROACH_FAILED, failed)
        self.ctx.note(
            f"approach of visitor {self.visitor} {how}: seek again "
            f"(not them for {retry_after:g} s)",
            incident=IncidentKind.APPROACH_FAILED,
        )


@register
class StartIntroduction(Leaf):
    """Send ``start_introduction``; ``icl`` is true while the face stream runs.

    Reads ``/icl`` (optional: False without a FaceStream scope) and ``/paused``
    (optional). SUCCESS once sent; RUNNING while the operator's pause lasts (no new
    content until ``resume``).
    """

    optional_reads = (keys.ICL, keys.PAUSED)
    world = World(inputs=(Channel.OPERATOR,), role=WorldRole.SPEAK, truthy=(keys.ICL.name,))

    def update(self) -> Status:
        if self.get(keys.PAUSED):
            self.feedback_message = "paused: the introduction waits"
            return RUNNING
        self.ctx.send(StartIntroductionCommand(bool(self.get(keys.ICL))))
        return SUCCESS


@register
class AskTour(Leaf):
    """Ask the visitor to join (``ask_tour``), worded by their engagement.

    Reads ``/engaged`` (optional): the decision over the introduction's face
    samples, None (sent as null) without face data; ``/paused`` (optional). SUCCESS
    once sent; RUNNING while the operator's pause lasts (no new content until
    ``resume``).
    """

    optional_reads = (keys.ENGAGED, keys.PAUSED)
    world = World(inputs=(Channel.OPERATOR,), role=WorldRole.SPEAK)

    def update(self) -> Status:
        if self.get(keys.PAUSED):
            self.feedback_message = "paused: the question waits"
            return RUNNING
        self.ctx.send(AskTourCommand(self.get(keys.ENGAGED)))
        return SUCCESS


@register
class WaitAnswer(Leaf):
    """Wait for the visitor's answer to ``ask_tour``.

    Reads ``/events``, ``/visitor``, ``/now``; writes ``/declined``. SUCCESS on
    ``user_positive``; FAILURE on ``user_negative`` or after ``timeout``
    (default: site ``timeouts.answer``), adding the visitor to ``/declined`` so
    that the next search looks for someone else.
    """

    class Params(Params):
        timeout: float | None = Timeout

    params: Params
    reads = (keys.EVENTS, keys.VISITOR, keys.NOW)
    optional_reads = (keys.DECLINED,)
    writes = (keys.DECLINED,)
    world = World(
        inputs=(Channel.FRONTEND, Channel.CLOCK),
        state=("since", "started", "timeout"),
        times=("started",),
        indexes=("since",),
        timer=lambda n: n.started + n.timeout,
        frontend=lambda n: (UserPositive(), UserNegative()),
        waits=True,
        ignores=(keys.DECLINED.name,),
        why="it reads /declined only to add to it",
    )

    def initialise(self) -> None:
        self.since = self.need(keys.EVENTS).last_index
        self.started = self.ctx.clock.now()
        self.timeout = self.params.timeout or self.ctx.site.timeouts.answer

    def update(self) -> Status:
        visitor = self.need(keys.VISITOR)
        for event in self.need(keys.EVENTS).since(self.since):
            if isinstance(event.message, UserPositive):
                self.ctx.note(f"visitor {visitor} wants the tour")
                return SUCCESS
            if isinstance(event.message, UserNegative):
                return self._decline(visitor, "does not want the tour")
        if self.need(keys.NOW) - self.started >= self.timeout:
            return self._decline(visitor, f"gave no answer within {self.timeout:g} s")
        return RUNNING

    def _decline(self, visitor: int, why: str) -> Status:
        self.set(keys.DECLINED, (self.get(keys.DECLINED) or frozenset()) | {visitor})
        self.ctx.note(
            f"visitor {visitor} {why}: seek again", incident=IncidentKind.VISITOR_DECLINED
        )
        return FAILURE
