"""Driving to POIs (``/GotoWayPoint`` answered on ``/FROG_response``), and skipping a stop."""

from __future__ import annotations

from pydantic import Field, ValidationInfo, field_validator

from frog_bt.behaviours.registry import register
from frog_bt.model import keys
from frog_bt.model.goals import Goal
from frog_bt.model.outcomes import IncidentKind
from frog_bt.model.wire import SUCCEEDED
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Leaf, Params, Status


def goal_state(sent: Goal, latest: Goal | None) -> Goal | None:
    """``sent`` as the board's ``/goal`` says it is now; None once a newer goal replaced
    it. Within the tick that sent it the board may still hold an older goal."""
    if latest is None or latest.id < sent.id:
        return sent
    return latest if latest.id == sent.id else None


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
class Navigate(Leaf):
    """Drive to ``poi``, choosing its time-of-day variant from the project clock.

    Sends ``/GotoWayPoint`` in initialise (a new goal replaces the active one), or once
    the operator's pause ends (``/paused``, optional: RUNNING until then).
    Reads ``/now`` and ``/goal`` (its result); writes ``/target`` (the logical POI),
    ``/waypoint`` (the variant chosen, e.g. ``POI1b``) and clears ``/skipped``. SUCCESS on
    ``/FROG_response`` 2; FAILURE on 3 or 4, when another goal replaces this
    one, or after ``timeout`` seconds (default: site ``timeouts.navigation``).
    """

    class Params(PoiParams):
        timeout: float | None = Field(None, gt=0, allow_inf_nan=False, description=(
            "seconds before it fails (default: site timeouts.navigation)"))

    reads = (keys.NOW, keys.GOAL)
    optional_reads = (keys.PAUSED,)
    writes = (keys.TARGET, keys.WAYPOINT, keys.SKIPPED)

    def initialise(self) -> None:
        self.goal: Goal | None = None
        self.timeout = self.params.timeout or self.ctx.site.timeouts.navigation
        self.set(keys.TARGET, self.params.poi)
        self.set(keys.SKIPPED, None)
        if not self.get(keys.PAUSED):
            self._send()

    def _send(self) -> None:
        site, clock = self.ctx.site, self.ctx.clock
        poi = self.params.poi
        waypoint = site.waypoint_for(poi, clock.local_time().time())
        self.goal = self.ctx.actions.goto(waypoint, site.pois[waypoint])
        self.set(keys.WAYPOINT, waypoint)
        self.ctx.note(f"go to {waypoint}" + (f" ({poi} at {clock.local_time():%H:%M})"
                                             if waypoint != poi else ""))

    def update(self) -> Status:
        if self.goal is None:
            if self.get(keys.PAUSED):
                self.feedback_message = f"paused: {self.params.poi} waits"
                return RUNNING
            self._send()
        assert self.goal is not None
        target = self.goal.target
        goal = goal_state(self.goal, self.get(keys.GOAL))
        if goal is None:
            self.ctx.note(f"navigation to {target} replaced by another goal")
            return FAILURE
        if goal.code == SUCCEEDED:
            self.ctx.note(f"arrived at {target}")
            return SUCCESS
        if goal.done:
            self.ctx.note(f"navigation to {target} {goal.state()}",
                          incident=IncidentKind.NAVIGATION_FAILED)
            return FAILURE
        if self.need(keys.NOW) - goal.sent_at >= self.timeout:
            self.ctx.note(f"navigation to {target}: no arrival within {self.timeout:g} s",
                          incident=IncidentKind.NAVIGATION_FAILED)
            return FAILURE
        self.feedback_message = f"{target}: {goal.state()}"
        return RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status in (INVALID, FAILURE):
            self.ctx.actions.cancel(getattr(self, "goal", None))


@register
class SkipStop(Leaf):
    """Give up on ``poi`` for this tour (its navigation kept failing).

    Writes ``/skipped`` = ``poi``. SUCCESS.
    """

    Params = PoiParams
    writes = (keys.SKIPPED,)

    def update(self) -> Status:
        self.set(keys.SKIPPED, self.params.poi)
        self.ctx.note(f"skipped {self.params.poi}: navigation kept failing",
                      incident=IncidentKind.STOP_SKIPPED, subject=self.params.poi)
        return SUCCESS


@register
class Skipped(Leaf):
    """Is ``poi`` being skipped? Reads ``/skipped`` (optional). SUCCESS if so, else FAILURE."""

    Params = PoiParams
    optional_reads = (keys.SKIPPED,)

    def update(self) -> Status:
        return SUCCESS if self.get(keys.SKIPPED) == self.params.poi else FAILURE
