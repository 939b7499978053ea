"""Commands to the robot over rosbridge, and the one goal awaiting ``/FROG_response``.

``/GotoWayPoint`` and ``/ApproachPeopleFar`` share ``/FROG_response`` and carry
no goal id, so at most one of them is pending at a time: a new goal replaces
the active one (CONTRACT §1), and a response that arrives while nothing is
pending is stale and ignored.

An answer is believed only when it fits what else the robot says (its pose, the order
of its answers: :mod:`frog_bt.engine.belief`); one that does not is told to
``on_doubt`` and never acted on.

Results reach the tree as values, not by mutation: the pre-tick step applies the
responses that arrived (:meth:`Actions.on_response`) and writes the newest goal's state
to :data:`frog_bt.model.keys.GOAL`, so every tick sees one consistent state. A leaf
keeps the :class:`Goal` it sent and compares ids: the key's goal is its own, a newer
one (it was replaced), or, within the tick that sent it, an older one.
"""

from __future__ import annotations

import copy
import itertools
import logging
import math
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

from frog_bt.clock import Clock
from frog_bt.config import Poi
from frog_bt.engine.belief import Judgement, Verdict, World, distance, judge
from frog_bt.model.goals import Goal
from frog_bt.model.ros import Pose
from frog_bt.model.wire import ACTIVE, SUCCEEDED, Response

log = logging.getLogger(__name__)

# (output role, value: the wire table encodes it, the goal it carries: goto and approach)
Publish = Callable[[str, object, "Goal | None"], None]
Doubt = Callable[[int, Goal, Judgement], None]  # an answer not believed: code, goal, why


class Held(NamedTuple):
    """What :class:`Actions` holds (:meth:`Actions.snapshot`)."""

    ids: itertools.count[int]
    pending: Goal | None
    latest: Goal | None
    before: Goal | None
    stale_responses: int
    doubted: int
    unconfirmed: tuple[int, float, int] | None
    last_approach_at: float


class Actions:
    """Publishes robot commands by role (``goto``, ``approach``, ``icl``, ``dock``) and
    tracks the one pending goal (a service: leaves learn results from the blackboard)."""

    def __init__(
        self,
        publish: Publish,
        clock: Clock,
        poses: Callable[[], int] = lambda: 0,
        on_doubt: Doubt | None = None,
    ) -> None:
        self._publish = publish
        self._clock = clock
        self._poses = poses  # /FROG_pose messages received so far
        self.on_doubt = on_doubt
        self._ids = itertools.count(1)
        self.pending: Goal | None = None
        self.latest: Goal | None = None  # the newest goal sent, with its latest response
        # the goal the pending one replaced while it was still open: its answer may come yet
        self.before: Goal | None = None
        self.stale_responses = 0
        self.doubted = 0  # answers not believed (stale by order, or not what the world shows)
        # an arrival heard before a pose that shows it: (goal id, when, poses by then)
        self.unconfirmed: tuple[int, float, int] | None = None
        self.last_approach_at = -math.inf  # project-clock time of the last approach sent

    def snapshot(self) -> Held:
        """Everything it holds, as values: :meth:`restore` gives it back (an explorer of
        every run, ``frog-bt verify``, steps back to a state this way). Goals are frozen."""
        return Held(
            copy.copy(self._ids),
            self.pending,
            self.latest,
            self.before,
            self.stale_responses,
            self.doubted,
            self.unconfirmed,
            self.last_approach_at,
        )

    def restore(self, held: Held) -> None:
        """Hold again what :meth:`snapshot` gave."""
        self._ids = copy.copy(held.ids)
        self.pending, self.latest, self.before = held.pending, held.latest, held.before
        self.stale_responses, self.doubted = held.stale_responses, held.doubted
        self.unconfirmed, self.last_approach_at = held.unconfirmed, held.last_approach_at

    def goto(self, waypoint: str, poi: Poi) -> Goal:
        now = self._clock.now()
        pose = Pose(now, "map", poi.x, poi.y, poi.z, poi.w)
        goal = self._replace(
            Goal(next(self._ids), "goto", waypoint, now, pose, poses=self._poses())
        )
        self._publish("goto", pose, goal)
        return goal

    def stop(self, here: Pose) -> Goal:
        """Stop driving now: a goal at the robot's own pose replaces the active one
        (CONTRACT §1: a new goal replaces the active one). The robot then stands."""
        goal = self._replace(
            Goal(next(self._ids), "goto", "(stop here)", here.stamp, here, poses=self._poses())
        )
        self._publish("goto", here, goal)
        return goal

    def approach(self, person_id: int) -> Goal:
        self.last_approach_at = now = self._clock.now()
        goal = self._replace(
            Goal(next(self._ids), "approach", str(person_id), now, person_id, poses=self._poses())
        )
        self._publish("approach", person_id, goal)
        return goal

    def resend_pending(self) -> Goal | None:
        """Publish the pending goal or approach again (after a reconnect its answer may
        have been lost while the link was down). The goal keeps waiting as before."""
        goal = self.pending
        if goal is not None:
            self._publish(goal.kind, goal.value, goal)  # the kind is the output role
            log.info("re-sent %s %s after a reconnect", goal.kind, goal.target)
        return goal

    def _replace(self, goal: Goal) -> Goal:
        latest = self.latest
        # An open goal replaced (or cancelled and then replaced): its answer may still come
        self.before = latest if latest is not None and not latest.done else None
        self.pending = self.latest = goal
        return goal

    def cancel(self, goal: Goal | None) -> None:
        """Stop waiting for ``goal``; a later response to it is stale."""
        if goal is not None and self.pending is not None and self.pending.id == goal.id:
            self.pending = None

    def on_response(self, code: int, at: float, world: World | None = None) -> Goal | None:
        """Apply one ``/FROG_response`` code; the goal it answered, if any. A code the
        contract does not know, or one that comes with nothing pending, is counted as
        stale; with ``world`` (what else the robot said), one that does not fit the
        pending goal is not believed (:func:`~frog_bt.engine.belief.judge`)."""
        goal = self.pending
        known = Response.of(code)
        if goal is None or known is None:
            self.stale_responses += 1
            log.debug(
                "ignored /FROG_response %d: %s",
                code,
                "nothing pending" if known is not None else "unknown code",
            )
            return None
        if world is not None:
            judgement = judge(goal, code, world, self.before)
            if judgement.verdict is not Verdict.BELIEVED:
                self.doubted += 1
                if judgement.verdict is Verdict.STALE:
                    self.stale_responses += 1
                    if self.before is not None and code != ACTIVE:
                        self.before = None  # the one answer it was still owed has come
                elif goal.kind == "goto" and code == SUCCEEDED:  # a later pose may show it
                    self.unconfirmed = (goal.id, at, world.poses_at_answer)
                if self.on_doubt is not None:
                    self.on_doubt(code, goal, judgement)
                return None
        return self._answered(goal, known, at)

    def confirm(self, world: World, grace: float) -> Goal | None:
        """An arrival not believed for want of a pose that shows it, believed now that one
        does: a pose received after the answer, within ``grace`` seconds of it, within
        the tolerance of the goal (a robot may publish the answer before the pose). The
        goal it ends, or None."""
        pending, unconfirmed = self.pending, self.unconfirmed
        if unconfirmed is None:
            return None
        goal_id, at, poses = unconfirmed
        if pending is None or pending.id != goal_id or world.now - at > grace:
            self.unconfirmed = None
            return None
        pose = world.pose
        if pose is None or world.poses_at_answer <= poses:
            return None
        if distance(pose.value, pending) > world.tolerance:
            return None
        self.unconfirmed = None
        log.info("arrival at %s believed: the pose shows it", pending.target)
        return self._answered(pending, SUCCEEDED, at)

    def _answered(self, goal: Goal, known: Response, at: float) -> Goal:
        """``goal`` with its answer ``known`` believed."""
        goal = replace(goal, code=known, answered_at=at, acknowledged=True)
        if known.terminal:  # this goal's end: an older goal's answer is no more due
            self.before = None
            self.unconfirmed = None
        self.pending = None if goal.done else goal
        if self.latest is not None and self.latest.id == goal.id:
            self.latest = goal
        return goal

    def dock(self, action: str) -> None:
        self._publish("dock", action, None)

    def icl(self, on: bool) -> None:
        self._publish("icl", "start" if on else "stop", None)
