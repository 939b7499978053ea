"""Driving to POIs (``/GotoWayPoint`` answered on ``/FROG_response``), and skipping a stop."""

from __future__ import annotations

from pydantic import Field, ValidationInfo, field_validator

from frog_bt.kernel.actions import CODE_NAMES, Request
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Leaf, Params, Status, register
from frog_bt.wire import SUCCEEDED


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

    Sends ``/GotoWayPoint`` in initialise (a new goal replaces the active one).
    Reads ``/now``; writes ``/target`` (the logical POI), ``/waypoint`` (the
    variant chosen, e.g. ``POI1b``) and clears ``/skipped``. SUCCESS on
    ``/FROG_response`` 2; FAILURE on 3 or 4, when another goal replaces this
    one, or after ``timeout`` seconds (default: site ``timeouts.navigation``).
    """

    class Params(PoiParams):
        timeout: float | None = Field(None, gt=0, allow_inf_nan=False, description=(
            "seconds before it fails (default: site timeouts.navigation)"))

    reads = ("/now",)
    writes = ("/target", "/waypoint", "/skipped")

    def initialise(self) -> None:
        site, clock = self.ctx.site, self.ctx.clock
        poi = self.params.poi
        waypoint = site.waypoint_for(poi, clock.local_time().time())
        self.request: Request | None = self.ctx.actions.goto(waypoint, site.pois[waypoint])
        self.timeout = self.params.timeout or site.timeouts.navigation
        self.set("/target", poi)
        self.set("/waypoint", waypoint)
        self.set("/skipped", None)
        self.ctx.note(f"go to {waypoint}" + (f" ({poi} at {clock.local_time():%H:%M})"
                                             if waypoint != poi else ""))

    def update(self) -> Status:
        request = self.request
        assert request is not None
        if request.code == SUCCEEDED:
            self.ctx.note(f"arrived at {request.target}")
            return SUCCESS
        if request.done:
            self.ctx.note(f"navigation to {request.target} {CODE_NAMES[request.code]}",
                          incident="navigation failed")
            return FAILURE
        if self.ctx.actions.pending is not request:
            self.ctx.note(f"navigation to {request.target} replaced by another goal")
            return FAILURE
        if self.get("/now") - request.sent_at >= self.timeout:
            self.ctx.note(f"navigation to {request.target}: no arrival within {self.timeout:g} s",
                          incident="navigation failed")
            return FAILURE
        self.feedback_message = f"{request.target}: {CODE_NAMES.get(request.code, 'sent')}"
        return RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status in (INVALID, FAILURE):
            self.ctx.actions.cancel(getattr(self, "request", None))


@register
class SkipStop(Leaf):
    """Give up on ``poi`` for this tour (its navigation kept failing).

    Writes ``/skipped`` = ``poi``. SUCCESS.
    """

    Params = PoiParams
    writes = ("/skipped",)

    def update(self) -> Status:
        self.set("/skipped", self.params.poi)
        self.ctx.note(f"skipped {self.params.poi}: navigation kept failing",
                      incident="stop skipped", subject=self.params.poi)
        return SUCCESS


@register
class Skipped(Leaf):
    """Is ``poi`` being skipped? Reads ``/skipped`` (optional). SUCCESS if so, else FAILURE."""

    Params = PoiParams
    optional_reads = ("/skipped",)

    def update(self) -> Status:
        return SUCCESS if self.get("/skipped") == self.params.poi else FAILURE
