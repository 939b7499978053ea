"""Finding, approaching and introducing a visitor at POI0 (seed: "POI0")."""

from __future__ import annotations

import math

from pydantic import Field

from frog_bt.frontend.messages import AskTour as AskTourCommand
from frog_bt.frontend.messages import StartIntroduction as StartIntroductionCommand
from frog_bt.frontend.messages import UserNegative, UserPositive
from frog_bt.kernel.actions import CODE_NAMES, Request
from frog_bt.kernel.blackboard import EventLog, Reading
from frog_bt.rosbridge.msgs import PersonDetection, PersonDetections, Pose
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Leaf, Params, Status, register
from frog_bt.wire import SUCCEEDED

Timeout = Field(None, gt=0, allow_inf_nan=False,
                description="seconds before it fails (default: the site's timeouts entry)")


def facing_visitor(persons: tuple[PersonDetection, ...], pose: Pose, lo: float, hi: float,
                   exclude: frozenset[int] = frozenset()) -> PersonDetection | None:
    """The nearest person facing the robot (``lo < orientation < hi``), not in ``exclude``."""
    candidates = [p for p in persons if lo < p.orientation < hi and p.id not in exclude]
    if not candidates:
        return None
    return min(candidates,
               key=lambda p: (math.hypot(p.position.x - pose.x, p.position.y - pose.y), p.id))


def cooling_down(failed: dict[int, float] | None, now: float, retry_after: float
                 ) -> frozenset[int]:
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

    reads = ("/persons", "/pose", "/now")
    optional_reads = ("/declined", "/approach_failed")
    writes = ("/visitor",)
    key_types = {"/visitor": int}

    def update(self) -> Status:
        cfg = self.ctx.site.recruit
        persons: Reading[PersonDetections] | None = self.get("/persons")
        pose: Reading[Pose] | None = self.get("/pose")
        now = self.get("/now")
        if pose is None:
            self.feedback_message = "no pose yet"
            return RUNNING
        if persons is None or persons.age(now) > cfg.detection_max_age:
            self.feedback_message = "no recent person detections"
            return RUNNING
        declined = self.get("/declined") or frozenset()
        cooling = cooling_down(self.get("/approach_failed"), now, cfg.retry_after)
        person = facing_visitor(persons.value.persons, pose.value, cfg.facing_min,
                                cfg.facing_max, declined | cooling)
        if person is None:
            seen = len(persons.value.persons)
            self.feedback_message = f"{seen} seen, none facing" + (
                f" but {', '.join(map(str, sorted(cooling)))} (approach failed)"
                if cooling else "")
            return RUNNING
        self.set("/visitor", person.id)
        self.ctx.note(f"visitor {person.id} faces the robot "
                      f"({person.orientation:.0f} deg), nearest of {len(persons.value.persons)}")
        return SUCCESS


@register
class ApproachVisitor(Leaf):
    """Approach ``/visitor`` with ``/ApproachPeopleFar``, never faster than the site allows.

    Reads ``/visitor``, ``/now``, ``/approach_failed``; writes ``/approach_failed``.
    The command goes out once ``recruit.approach_interval`` seconds have passed
    since the previous approach (RUNNING until then). SUCCESS on
    ``/FROG_response`` 2; FAILURE on 3 or 4, or after ``timeout`` (default: site
    ``timeouts.approach``), recording the person in ``/approach_failed`` so that
    the next search passes them over for ``recruit.retry_after`` seconds.
    """

    class Params(Params):
        timeout: float | None = Timeout

    reads = ("/visitor", "/now")
    optional_reads = ("/approach_failed",)
    writes = ("/approach_failed",)
    key_types = {"/visitor": int, "/approach_failed": dict}

    def initialise(self) -> None:
        self.visitor = self.get("/visitor")
        self.request: Request | None = None
        self.timeout = self.params.timeout or self.ctx.site.timeouts.approach
        self._send_when_due()

    def _send_when_due(self) -> None:
        actions, now = self.ctx.actions, self.ctx.clock.now()
        due = actions.last_approach_at + self.ctx.site.recruit.approach_interval
        if now < due:
            self.feedback_message = f"next approach in {due - now:.1f} s"
            return
        self.request = actions.approach(self.visitor)
        self.ctx.note(f"approach visitor {self.visitor}")

    def update(self) -> Status:
        if self.request is None:
            self._send_when_due()
            if self.request is None:
                return RUNNING
        request = self.request
        if request.code == SUCCEEDED:
            self.ctx.note(f"approached visitor {self.visitor}")
            return SUCCESS
        if request.done or self.ctx.actions.pending is not request:
            return self._failed(CODE_NAMES.get(request.code, "replaced"))
        if self.get("/now") - request.sent_at >= self.timeout:
            return self._failed("timed out")
        return RUNNING

    def _failed(self, how: str) -> Status:
        failed = dict(self.get("/approach_failed") or {})
        now = self.get("/now")
        retry_after = self.ctx.site.recruit.retry_after
        failed = {pid: at for pid, at in failed.items() if now - at < retry_after}
        failed[self.visitor] = now
        self.set("/approach_failed", failed)
        self.ctx.note(f"approach of visitor {self.visitor} {how}: seek again "
                      f"(not them for {retry_after:g} s)", incident="approach failed")
        return FAILURE

    def terminate(self, new_status: Status) -> None:
        if new_status in (INVALID, FAILURE):
            self.ctx.actions.cancel(getattr(self, "request", None))


@register
class StartIntroduction(Leaf):
    """Send ``start_introduction``; ``icl`` is true while the face stream runs.

    Reads ``/icl`` (optional: False without a FaceStream scope). SUCCESS.
    """

    optional_reads = ("/icl",)

    def update(self) -> Status:
        self.ctx.send(StartIntroductionCommand(bool(self.get("/icl"))))
        return SUCCESS


@register
class AskTour(Leaf):
    """Ask the visitor to join (``ask_tour``), worded by their engagement.

    Reads ``/engaged`` (optional): the decision over the introduction's face
    samples, None (sent as null) without face data. SUCCESS.
    """

    optional_reads = ("/engaged",)

    def update(self) -> Status:
        self.ctx.send(AskTourCommand(self.get("/engaged")))
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

    reads = ("/events", "/visitor", "/now")
    optional_reads = ("/declined",)
    writes = ("/declined",)
    key_types = {"/visitor": int, "/declined": frozenset}

    def initialise(self) -> None:
        events: EventLog = self.get("/events")
        self.since = events.last_index
        self.started = self.ctx.clock.now()
        self.timeout = self.params.timeout or self.ctx.site.timeouts.answer

    def update(self) -> Status:
        events: EventLog = self.get("/events")
        visitor = self.get("/visitor")
        for event in events.since(self.since):
            if isinstance(event.message, UserPositive):
                self.ctx.note(f"visitor {visitor} wants the tour")
                return SUCCESS
            if isinstance(event.message, UserNegative):
                return self._decline(visitor, "does not want the tour")
        if self.get("/now") - self.started >= self.timeout:
            return self._decline(visitor, f"gave no answer within {self.timeout:g} s")
        return RUNNING

    def _decline(self, visitor: int, why: str) -> Status:
        self.set("/declined", (self.get("/declined") or frozenset()) | {visitor})
        self.ctx.note(f"visitor {visitor} {why}: seek again", incident="visitor declined")
        return FAILURE
