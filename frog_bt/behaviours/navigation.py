"""Driving to POIs (``/GotoWayPoint`` answered on ``/FROG_response``), and skipping a stop."""

from __future__ import annotations

import math

from pydantic import Field, ValidationInfo, field_validator

from frog_bt.behaviours.goal_leaf import Failure, GoalLeaf
from frog_bt.behaviours.registry import register
from frog_bt.model import keys
from frog_bt.model.goals import Goal
from frog_bt.model.outcomes import IncidentKind
from frog_bt.tree.leaf import FAILURE, SUCCESS, Leaf, Params, Status
from frog_bt.tree.world import Channel, Role, World


class PoiParams(Params):
    poi: str = Field(description="a POI or time-of-day variant of the site (config pois)")

    @field_validator("poi")
    @classmethod
    def _known(cls, value: str, info: ValidationInfo) -> str:
        site = (info.context or {}).get("site")
        if site is not None and value not in site.pois and value not in site.variants:
            known = ", ".join(sorted({*site.pois, *site.variants}))
            raise ValueError(f"unknown POI {value!r} (known: {known})")
        return value


@register
class Navigate(GoalLeaf):
    """Drive to ``poi``, choosing its time-of-day variant from the project clock.

    Sends ``/GotoWayPoint`` in initialise (a new goal replaces the active one), or once
    the operator's pause ends (``/paused``, optional: RUNNING until then). A pause while
    it drives stops the robot at once (a goal at its own pose, ``/pose``); the goal goes
    out again when the pause ends. Reads ``/now`` and ``/goal`` (its result); writes
    ``/target`` (the logical POI), ``/waypoint`` (the variant chosen, e.g. ``POI1b``) and
    clears ``/skipped``. SUCCESS on ``/FROG_response`` 2; FAILURE on 3 or 4, when another
    goal replaces this one, or after ``timeout`` seconds (default: site ``timeouts.navigation``).
    """

    class Params(PoiParams):
        timeout: float | None = Field(
            None,
            gt=0,
            allow_inf_nan=False,
            description=("seconds before it fails (default: site timeouts.navigation)"),
        )

    params: Params
    reads = (keys.NOW, keys.GOAL)
    optional_reads = (keys.PAUSED, keys.POSE)
    writes = (keys.TARGET, keys.WAYPOINT, keys.SKIPPED)
    waits_while_paused = True
    world = World(
        inputs=(Channel.GOAL, Channel.POSE, Channel.OPERATOR, Channel.CLOCK),
        state=GoalLeaf.world.state,
        times=GoalLeaf.world.times,
        timer=GoalLeaf.world.timer,
        active="sent_at",
        role=Role.DRIVE,
        why="the robot arrives (a pose at the waypoint, then /FROG_response 2) or fails "
        "(3) at the next tick, or the timeout runs out: how long a drive takes is left out",
    )

    def default_timeout(self) -> float:
        return self.ctx.site.timeouts.navigation

    def begin(self) -> None:
        self.set(keys.TARGET, self.params.poi)
        self.set(keys.SKIPPED, None)

    def paused_feedback(self) -> str:
        return f"paused: {self.params.poi} waits"

    def send(self) -> Goal:
        site, clock = self.ctx.site, self.ctx.clock
        poi = self.params.poi
        waypoint = site.waypoint_for(poi, clock.local_time().time())
        goal = self.ctx.actions.goto(waypoint, site.pois[waypoint])
        self.set(keys.WAYPOINT, waypoint)
        self.ctx.note(
            f"go to {waypoint}"
            + (f" ({poi} at {clock.local_time():%H:%M})" if waypoint != poi else "")
        )
        return goal

    def succeeded(self) -> None:
        assert self.goal is not None
        self.ctx.note(f"arrived at {self.goal.target}")

    def failed(self, why: Failure) -> None:
        assert self.goal is not None
        target = self.goal.target
        if why is Failure.REPLACED:
            self.ctx.note(f"navigation to {target} replaced by another goal")
        elif why is Failure.TIMED_OUT:
            self.ctx.note(
                f"navigation to {target}: no arrival within {self.timeout:g} s",
                incident=IncidentKind.NAVIGATION_FAILED,
            )
        else:
            assert self.latest is not None
            self.ctx.note(
                f"navigation to {target} {self.latest.state()}",
                incident=IncidentKind.NAVIGATION_FAILED,
            )

    def progress(self) -> str:
        assert self.goal is not None and self.latest is not None
        return f"{self.goal.target}: {self.latest.state()}"


@register
class AtPoi(Leaf):
    """Is the robot at ``poi`` (its time-of-day variant now)?

    Reads ``/pose`` (optional). SUCCESS when the latest pose is within
    ``navigation.tolerance`` metres of it; FAILURE otherwise, and with no pose (where
    the robot is cannot be believed without one).
    """

    Params = PoiParams
    params: PoiParams
    optional_reads = (keys.POSE,)
    world = World(
        inputs=(Channel.POSE,),
        places=lambda n: (n.ctx.site.waypoint_for(n.params.poi, n.ctx.clock.local_time().time()),),
        why="where the robot is: at the waypoint of its last believed arrival (at the dock "
        "at first), or away from every waypoint after a failed drive",
    )

    def update(self) -> Status:
        site = self.ctx.site
        waypoint = site.waypoint_for(self.params.poi, self.ctx.clock.local_time().time())
        reading = self.get(keys.POSE)
        if reading is None:
            self.feedback_message = "no pose yet"
            return FAILURE
        here, there = reading.value, site.pois[waypoint]
        away = math.hypot(here.x - there.x, here.y - there.y)
        self.feedback_message = f"{away:.1f} m from {waypoint}"
        return SUCCESS if away <= site.navigation.tolerance else FAILURE


@register
class SkipStop(Leaf):
    """Give up on ``poi`` for this tour (its navigation kept failing).

    Writes ``/skipped`` = ``poi``. SUCCESS.
    """

    Params = PoiParams
    params: PoiParams
    writes = (keys.SKIPPED,)
    world = World()

    def update(self) -> Status:
        self.set(keys.SKIPPED, self.params.poi)
        self.ctx.note(
            f"skipped {self.params.poi}: navigation kept failing",
            incident=IncidentKind.STOP_SKIPPED,
            subject=self.params.poi,
        )
        return SUCCESS


@register
class Skipped(Leaf):
    """Is ``poi`` being skipped? Reads ``/skipped`` (optional). SUCCESS if so, else FAILURE."""

    Params = PoiParams
    params: PoiParams
    optional_reads = (keys.SKIPPED,)
    world = World()

    def update(self) -> Status:
        return SUCCESS if self.get(keys.SKIPPED) == self.params.poi else FAILURE
