"""Tour bookkeeping leaves: front-end readiness, tour status, waiting for events."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from frog_bt.config import Timeouts
from frog_bt.frontend.messages import EVENTS, Tour
from frog_bt.kernel.blackboard import EventLog
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status, register


@register
class WaitFrontendIdle(Leaf):
    """Wait until the front end says it is ready (``frontend_idle``) and the robot is fit.

    Reads ``/frontend_ready``, ``/now`` and ``/diagnostics``: while fresh
    diagnostics show a fault or a battery below ``safety.battery_resume``, it
    waits (charging) and says so. Stale or missing diagnostics do not hold a
    tour back. RUNNING until ready, then SUCCESS.
    """

    reads = ("/frontend_ready", "/now", "/diagnostics")

    def update(self) -> Status:
        cfg = self.ctx.site.safety
        reading = self.get("/diagnostics")
        diagnostics = (reading.value if reading is not None
                       and reading.age(self.get("/now")) <= cfg.diagnostics_max_age else None)
        if diagnostics is not None and diagnostics.faults:
            self.feedback_message = "fault: " + "; ".join(diagnostics.faults)
            return RUNNING
        if (diagnostics is not None and diagnostics.battery is not None
                and diagnostics.battery < cfg.battery_resume):
            self.feedback_message = (f"charging: battery {diagnostics.battery:.0f}% "
                                     f"< {cfg.battery_resume:g}%")
            return RUNNING
        if self.get("/frontend_ready"):
            return SUCCESS
        self.feedback_message = "waiting for frontend_idle"
        return RUNNING


@register
class TourStatus(Leaf):
    """Send ``tour`` with ``state`` and ``reason`` to the front end.

    An ``aborted`` tour without a ``reason`` gives ``/abort_reason`` (optional read).
    Ending or aborting a tour clears the checkpointed progress.

    Writes ``/frontend_ready`` (False: the next tour needs a fresh
    ``frontend_idle``), ``/declined`` and ``/special_done`` (cleared when a tour
    starts) and ``/tour_state``. SUCCESS.
    """

    class Params(Params):
        state: Literal["started", "ended", "aborted"] = Field(
            description="the tour state sent to the front end")
        reason: str = Field("", description="why (with aborted; default: the abort reason)")

    optional_reads = ("/abort_reason",)
    writes = ("/frontend_ready", "/declined", "/special_done", "/tour_state")

    def update(self) -> Status:
        p = self.params
        reason = p.reason or (self.get("/abort_reason") or "" if p.state == "aborted" else "")
        self.ctx.send(Tour(p.state, reason))
        self.ctx.note(f"tour {p.state}" + (f": {reason}" if reason else ""))
        if p.state != "started":
            self.ctx.progress.clear()
        self.set("/frontend_ready", False)
        self.set("/tour_state", p.state)
        self.ctx.tour_state, self.ctx.tour_reason = p.state, reason
        if p.state == "started":
            self.set("/declined", frozenset())
            self.set("/special_done", frozenset())
        return SUCCESS


TimeoutName = Literal[tuple(Timeouts.model_fields)]  # type: ignore[valid-type]


@register
class WaitEvent(Leaf):
    """Wait for a front-end event that arrives after this leaf starts; never for ever.

    Reads ``/events`` and ``/now``. SUCCESS when an ``event`` arrives. After
    ``timeout`` — seconds of project-clock time, or the name of a site
    ``timeouts`` entry (``introduction``) — it returns ``on_timeout`` (FAILURE
    by default; SUCCESS to carry on as if the event had come, e.g. ask the
    visitor anyway when ``finish_introduction`` was lost) and notes why.
    """

    class Params(Params):
        event: Literal[tuple(EVENTS)] = Field(  # type: ignore[valid-type]
            description="the front-end event waited for")
        timeout: Annotated[float, Field(gt=0, allow_inf_nan=False)] | TimeoutName = Field(
            description="seconds, or the name of a site timeouts entry")
        on_timeout: Literal["failure", "success"] = Field(
            "failure", description="what a wait that ran out returns")

    reads = ("/events", "/now")

    def initialise(self) -> None:
        events: EventLog = self.get("/events")
        self.since = events.last_index
        self.started = self.ctx.clock.now()
        timeout = self.params.timeout
        self.timeout = self.ctx.site.timeout(timeout) if isinstance(timeout, str) else timeout

    def update(self) -> Status:
        events: EventLog = self.get("/events")
        if events.first_since(self.since, EVENTS[self.params.event]) is not None:
            return SUCCESS
        if self.get("/now") - self.started >= self.timeout:
            success = self.params.on_timeout == "success"
            self.ctx.note(f"no {self.params.event} within {self.timeout:g} s"
                          + (": carrying on" if success else ""), incident="event missing")
            return SUCCESS if success else FAILURE
        self.feedback_message = f"waiting for {self.params.event}"
        return RUNNING
