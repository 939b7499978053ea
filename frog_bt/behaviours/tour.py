"""Tour bookkeeping leaves: front-end readiness, tour status, waiting for events."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import Field

from frog_bt.behaviours.registry import register
from frog_bt.config import Timeouts
from frog_bt.model import keys
from frog_bt.model.frontend import EVENTS, FrontendIdle, Tour
from frog_bt.model.outcomes import IncidentKind, TourState
from frog_bt.model.progress import EMPTY
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status
from frog_bt.tree.world import Channel, Role, World


@register
class WaitFrontendIdle(Leaf):
    """Wait until the front end says it is ready (``frontend_idle``) and the robot is fit.

    Reads ``/frontend_ready``, ``/now`` and ``/diagnostics``: while fresh
    diagnostics show a fault or a battery below ``safety.battery_resume``, it
    waits (charging) and says so. Stale or missing diagnostics do not hold a
    tour back. RUNNING until ready, then SUCCESS.
    """

    reads = (keys.FRONTEND_READY, keys.NOW, keys.DIAGNOSTICS)
    world = World(
        inputs=(Channel.FRONTEND, Channel.DIAGNOSTICS),
        frontend=lambda n: (FrontendIdle(),),
        waits=True,
        role=Role.IDLE,
        why="battery: low (below safety.battery_low) or full; a fault or none",
    )

    def update(self) -> Status:
        cfg = self.ctx.site.safety
        reading = self.get(keys.DIAGNOSTICS)
        diagnostics = (
            reading.value
            if reading is not None and reading.age(self.need(keys.NOW)) <= cfg.diagnostics_max_age
            else None
        )
        if diagnostics is not None and diagnostics.faults:
            self.feedback_message = "fault: " + "; ".join(diagnostics.faults)
            return RUNNING
        if (
            diagnostics is not None
            and diagnostics.battery is not None
            and diagnostics.battery < cfg.battery_resume
        ):
            self.feedback_message = (
                f"charging: battery {diagnostics.battery:.0f}% < {cfg.battery_resume:g}%"
            )
            return RUNNING
        if self.get(keys.FRONTEND_READY):
            return SUCCESS
        self.feedback_message = "waiting for frontend_idle"
        return RUNNING


@register
class TourStatus(Leaf):
    """Send ``tour`` with ``state`` and ``reason`` to the front end.

    An ``aborted`` tour without a ``reason`` gives ``/abort_reason`` (optional read).
    Ending or aborting a tour clears the checkpointed progress (``/progress``).

    Writes ``/frontend_ready`` (False: the next tour needs a fresh
    ``frontend_idle``), ``/tour_state`` and ``/tour_reason``. SUCCESS.
    """

    class Params(Params):
        state: Literal["started", "ended", "aborted"] = Field(
            description="the tour state sent to the front end"
        )
        reason: str = Field("", description="why (with aborted; default: the abort reason)")

    params: Params
    optional_reads = (keys.ABORT_REASON,)
    writes = (keys.FRONTEND_READY, keys.TOUR_STATE, keys.TOUR_REASON, keys.PROGRESS)
    world = World(
        ignores=(keys.ABORT_REASON.name,),
        why="of the abort's reason it sends the words to the front end: no outcome",
    )

    def update(self) -> Status:
        p = self.params
        state = TourState(p.state)
        abort = self.get(keys.ABORT_REASON) if state is TourState.ABORTED else None
        reason = p.reason or (abort.text if abort is not None else "")
        self.ctx.send(Tour(state, reason))
        self.ctx.note(f"tour {state}" + (f": {reason}" if reason else ""))
        if state is not TourState.STARTED:
            self.set(keys.PROGRESS, EMPTY)
        self.set(keys.FRONTEND_READY, False)
        self.set(keys.TOUR_STATE, state)
        self.set(keys.TOUR_REASON, reason)
        return SUCCESS


if TYPE_CHECKING:
    TimeoutName = str  # to the checker; pydantic checks the name against Timeouts' fields
else:
    TimeoutName = Literal[tuple(Timeouts.model_fields)]


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
            description="the front-end event waited for"
        )
        timeout: Annotated[float, Field(gt=0, allow_inf_nan=False)] | TimeoutName = Field(
            description="seconds, or the name of a site timeouts entry"
        )
        on_timeout: Literal["failure", "success"] = Field(
            "failure", description="what a wait that ran out returns"
        )

    params: Params
    reads = (keys.EVENTS, keys.NOW)
    world = World(
        inputs=(Channel.FRONTEND, Channel.CLOCK),
        state=("since", "started", "timeout"),
        times=("started",),
        indexes=("since",),
        timer=lambda n: n.started + n.timeout,
        frontend=lambda n: (EVENTS[n.params.event](),),
        waits=True,
    )

    def initialise(self) -> None:
        self.since = self.need(keys.EVENTS).last_index
        self.started = self.ctx.clock.now()
        timeout = self.params.timeout
        self.timeout = self.ctx.site.timeout(timeout) if isinstance(timeout, str) else timeout

    def update(self) -> Status:
        events = self.need(keys.EVENTS)
        if events.first_since(self.since, EVENTS[self.params.event]) is not None:
            return SUCCESS
        if self.need(keys.NOW) - self.started >= self.timeout:
            success = self.params.on_timeout == "success"
            self.ctx.note(
                f"no {self.params.event} within {self.timeout:g} s"
                + (": carrying on" if success else ""),
                incident=IncidentKind.EVENT_MISSING,
            )
            return SUCCESS if success else FAILURE
        self.feedback_message = f"waiting for {self.params.event}"
        return RUNNING
