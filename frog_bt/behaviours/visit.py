"""At a stop: is the visitor still with us, and the stop's content."""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field

from frog_bt.behaviours.navigation import PoiParams
from frog_bt.behaviours.registry import register
from frog_bt.model import keys
from frog_bt.model.frontend import ContentDone, FrontendIdle, StartPoi
from frog_bt.model.frontend import FinishPoi as FinishPoiCommand
from frog_bt.model.outcomes import IncidentKind
from frog_bt.model.ros import Pose, TrackedPeople
from frog_bt.tree import leaf
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.world import Channel, Role, World


def someone_within(people: TrackedPeople, pose: Pose, radius: float) -> bool:
    return any(
        math.hypot(p.position.x - pose.x, p.position.y - pose.y) <= radius for p in people.people
    )


@register
class VisitorFollows(Leaf):
    """Is the visitor still following? Someone tracked by the laser near the robot.

    Reads ``/people``, ``/pose``, ``/now``. SUCCESS as soon as a tracked person is
    within ``radius`` metres (default: site ``follow.radius``); RUNNING for up to
    ``grace`` seconds while nobody is (default: site ``follow.grace``), then FAILURE.
    Stale tracks or pose (``safety.people_max_age``, ``safety.pose_max_age``) are
    not evidence either way: it waits and says so, and if tracking is still
    stale after ``grace`` it gives the visitor the benefit of the doubt (SUCCESS,
    with a note) rather than abandon them over a sensor dropout.
    """

    class Params(leaf.Params):  # qualified: mypy may take a bare Params for this one
        radius: float | None = Field(
            None,
            gt=0,
            allow_inf_nan=False,
            description=(
                "metres around the robot a follower is looked for (default: site follow.radius)"
            ),
        )
        grace: float | None = Field(
            None,
            ge=0,
            allow_inf_nan=False,
            description=(
                "seconds nobody may be seen before the visitor counts as lost "
                "(default: site follow.grace)"
            ),
        )

    params: Params
    reads = (keys.PEOPLE, keys.POSE, keys.NOW)
    world = World(
        inputs=(Channel.VISITOR, Channel.POSE, Channel.CLOCK),
        state=("radius", "grace", "started"),
        times=("started",),
        timer=lambda n: n.started + n.grace,
        waits=True,
        why="distance: someone tracked at the robot, or nobody near",
    )

    def initialise(self) -> None:
        cfg = self.ctx.site.follow
        self.radius = self.params.radius or cfg.radius
        self.grace = cfg.grace if self.params.grace is None else self.params.grace
        self.started = self.ctx.clock.now()

    def update(self) -> Status:
        people = self.get(keys.PEOPLE)
        pose = self.get(keys.POSE)
        now = self.need(keys.NOW)
        safety = self.ctx.site.safety
        fresh = (
            people is not None
            and people.age(now) <= safety.people_max_age
            and pose is not None
            and pose.age(now) <= safety.pose_max_age
        )
        if fresh and people and pose and someone_within(people.value, pose.value, self.radius):
            return SUCCESS
        if now - self.started >= self.grace:
            if not fresh:
                self.ctx.note(
                    "laser tracking or pose stale: assuming the visitor follows",
                    incident=IncidentKind.STALE_INPUT,
                )
                return SUCCESS
            self.ctx.note(
                f"nobody within {self.radius:g} m for {self.grace:g} s: "
                "visitor lost, back to recruit",
                incident=IncidentKind.VISITOR_LOST,
            )
            return FAILURE
        self.feedback_message = (
            "waiting for the visitor to catch up"
            if fresh
            else "laser tracking or pose stale: waiting"
        )
        return RUNNING


@register
class PlayContent(Leaf):
    """Play part ``part`` of ``poi``'s content and wait until it is done.

    Sends ``start_poi`` (with the waypoint chosen on the way, ``/waypoint``) in
    initialise, or once the operator's pause ends (``/paused``: RUNNING until then).
    Reads ``/events``, ``/now`` and, optionally, ``/waypoint`` and ``/paused``. SUCCESS on the
    matching ``content_done``, or after ``timeout`` seconds (default: site
    ``timeouts.content``) with a note: a silent front end must not stop the tour.
    Interrupted while playing, it sends ``finish_poi`` to stop the content.
    """

    class Params(PoiParams):
        part: Literal["a", "b"] = Field("a", description="a: the content; b: its extension")
        timeout: float | None = Field(
            None,
            gt=0,
            allow_inf_nan=False,
            description=(
                "seconds before going on without content_done (default: site timeouts.content)"
            ),
        )

    params: Params
    reads = (keys.EVENTS, keys.NOW)
    optional_reads = (keys.WAYPOINT, keys.PAUSED)
    world = World(
        inputs=(Channel.FRONTEND, Channel.OPERATOR, Channel.CLOCK),
        state=("playing", "waypoint", "since", "started", "timeout", "restart_seen"),
        times=("started",),
        indexes=("since", "restart_seen"),
        timer=lambda n: n.started + n.timeout if getattr(n, "playing", False) else None,
        frontend=lambda n: (
            (ContentDone(n.params.poi, n.params.part),) if getattr(n, "playing", False) else ()
        ),
        active="playing",
        waits=True,
        role=Role.CONTENT,
        ignores=(keys.WAYPOINT.name, "waypoint"),
        why="the waypoint (the variant driven to) goes to the front end with start_poi: "
        "no outcome depends on it",
    )

    def initialise(self) -> None:
        self.playing = False
        self.waypoint = self.get(keys.WAYPOINT) or self.params.poi
        if not self.get(keys.PAUSED):
            self._start()

    def _start(self) -> None:
        p = self.params
        self.playing = True
        self.since = self.need(keys.EVENTS).last_index
        self.started = self.ctx.clock.now()
        self.timeout = p.timeout or self.ctx.site.timeouts.content
        self.restart_seen = self.since
        self.ctx.send(StartPoi(p.poi, self.waypoint, p.part))

    def terminate(self, new_status: Status) -> None:
        # Interrupted (a tour aborted, a shutdown): stop the content that is playing.
        if new_status == INVALID and self.status == RUNNING and getattr(self, "playing", False):
            self.ctx.send(FinishPoiCommand(self.params.poi))
            self.ctx.note(f"{self.params.poi} interrupted: content stopped")

    def update(self) -> Status:
        p = self.params
        if not self.playing:
            if self.get(keys.PAUSED):
                self.feedback_message = f"paused: {p.poi} part {p.part} waits"
                return RUNNING
            self._start()
        events = self.need(keys.EVENTS)
        if events.first_since(self.since, ContentDone, poi=p.poi, part=p.part) is not None:
            return SUCCESS
        restart = events.first_since(self.restart_seen, FrontendIdle)
        if restart is not None:
            # the front end restarted and lost what it was playing: play it again
            self.restart_seen = restart.index
            self.ctx.send(StartPoi(p.poi, self.waypoint, p.part))
            self.ctx.note(f"front end restarted: {p.poi} part {p.part} sent again")
        if self.need(keys.NOW) - self.started >= self.timeout:
            self.ctx.note(
                f"{p.poi} part {p.part}: no content_done within {self.timeout:g} s, going on",
                incident=IncidentKind.CONTENT_TIMEOUT,
            )
            return SUCCESS
        self.feedback_message = f"playing {p.poi} part {p.part}"
        return RUNNING


@register
class FinishPoi(Leaf):
    """Send ``finish_poi`` for ``poi``. SUCCESS."""

    Params = PoiParams
    params: PoiParams
    world = World()

    def update(self) -> Status:
        self.ctx.send(FinishPoiCommand(self.params.poi))
        return SUCCESS
