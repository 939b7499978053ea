"""Never strand a visitor or the robot: abort politely, give up cleanly, resume after a restart."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import py_trees
from pydantic import Field

from frog_bt.frontend.messages import Tour
from frog_bt.kernel.blackboard import Reading
from frog_bt.rosbridge.msgs import Diagnostics
from frog_bt.tree.decorators import FrogDecorator, register_decorator
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status, register

log = logging.getLogger(__name__)


def fresh_diagnostics(reading: Reading[Diagnostics] | None, now: float,
                      max_age: float) -> Diagnostics | None:
    """The diagnostics if recent enough to act on, else None (stale data is not acted on)."""
    if reading is None or reading.age(now) > max_age:
        return None
    return reading.value


@register
class MustAbort(Leaf):
    """Must the tour be aborted? (battery low or an electronics fault, during a tour)

    Reads ``/diagnostics`` (only when fresher than ``safety.diagnostics_max_age``),
    ``/now``, ``/tour_state`` (optional) and ``/abort_reason`` (optional).
    Writes ``/abort_reason``. SUCCESS while an abort is under way (the reason
    is latched until :class:`ClearAbort`); FAILURE otherwise.
    """

    reads = ("/diagnostics", "/now")
    optional_reads = ("/tour_state", "/abort_reason")
    writes = ("/abort_reason",)

    def update(self) -> Status:
        if self.get("/abort_reason"):
            return SUCCESS
        if self.get("/tour_state") != "started":
            return FAILURE
        cfg = self.ctx.site.safety
        diagnostics = fresh_diagnostics(self.get("/diagnostics"), self.get("/now"),
                                        cfg.diagnostics_max_age)
        if diagnostics is None:
            self.feedback_message = "diagnostics stale or missing: not acted on"
            return FAILURE
        reason = ""
        if diagnostics.faults:
            reason = "electronics fault: " + "; ".join(diagnostics.faults)
        elif diagnostics.battery is not None and diagnostics.battery < cfg.battery_low:
            reason = f"battery {diagnostics.battery:.0f}% below {cfg.battery_low:g}%"
        if not reason:
            self.feedback_message = ""
            return FAILURE
        self.set("/abort_reason", reason)
        self.ctx.note(f"abort the tour: {reason}", incident="tour aborted")
        return SUCCESS


@register
class ClearAbort(Leaf):
    """The abort is done: clear ``/abort_reason`` (kept as ``/abort_reason_last``). SUCCESS."""

    optional_reads = ("/abort_reason",)
    writes = ("/abort_reason", "/abort_reason_last")

    def update(self) -> Status:
        self.set("/abort_reason_last", self.get("/abort_reason"))
        self.set("/abort_reason", None)
        return SUCCESS


@register
class GiveUp(Leaf):
    """The tour cannot go on: tell the front end why (``tour aborted``) and fail.

    The reason is the latest decision note (e.g. "undock failed"). Writes
    ``/tour_state``. FAILURE, always: the executive stops with that reason.
    """

    writes = ("/tour_state",)

    def update(self) -> Status:
        reason = self.ctx.notes[-1][1] if self.ctx.notes else "the tour cannot go on"
        self.ctx.send(Tour("aborted", reason))
        self.set("/tour_state", "aborted")
        self.ctx.progress.clear()
        self.ctx.gave_up = reason
        self.ctx.note(f"giving up: {reason}", incident="gave up")
        self.feedback_message = reason
        return FAILURE


@register
class ConfirmResume(Leaf):
    """Decide whether to resume the tour of a checkpoint left by a previous run.

    Only a robot that reports itself away from the dock (``/docking`` not
    ``docked``) within ``checkpoint.confirm`` seconds resumes; otherwise the
    checkpoint is dropped and a fresh tour starts. Reads ``/docking``, ``/now``.
    SUCCESS once decided (at once without a checkpoint).
    """

    reads = ("/docking", "/now")

    def initialise(self) -> None:
        self.started = self.ctx.clock.now()

    def update(self) -> Status:
        resume = self.ctx.resume
        if resume is None:
            return SUCCESS
        state: Reading[str] | None = self.get("/docking")
        if state is not None and state.value not in ("docked", "docking"):
            announce = resume.announce([stop.poi for stop in self.ctx.site.tour.stops])
            self.ctx.resumed = announce
            self.ctx.note(f"{announce} ({resume.describe()})", incident="resumed")
            log.warning("%s", announce)
            return SUCCESS
        if state is not None or self.get("/now") - self.started >= self.ctx.site.checkpoint.confirm:
            why = f"the robot is {state.value}" if state else "no docking state"
            self.ctx.note(f"checkpoint dropped ({why}): a fresh tour")
            self.ctx.resume = None
            self.ctx.progress.clear()
            return SUCCESS
        self.feedback_message = "checkpoint found: waiting for the docking state"
        return RUNNING


@register_decorator
class Checkpointed(FrogDecorator):
    """A part of the tour recorded in the checkpoint as ``checkpoint`` when it succeeds.

    A tour resumed from a checkpoint skips it (SUCCESS without running the
    child) when the checkpoint says it was done, restoring ``/visitor``.
    Running it again drops it and every later checkpoint from the progress.
    Reads ``/visitor`` (optional); writes ``/visitor``. Returns the child's status.
    """

    class Params(Params):
        checkpoint: str = Field(min_length=1, description=(
            "the part's name in the checkpoint (unique in the tree)"))

    optional_reads = ("/visitor",)
    writes = ("/visitor",)
    key_types = {"/visitor": int}
    skips_child = True  # resumed: SUCCESS without the child (the data-flow check)

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        if self.status != RUNNING and self._resumed_past():
            self.status = SUCCESS
            yield self
            return
        yield from super().tick()

    def _resumed_past(self) -> bool:
        resume, name = self.ctx.resume, self.params.checkpoint
        if resume is None or name not in resume.done:
            return False
        resume.done.discard(name)
        if resume.visitor is not None:
            self.set("/visitor", resume.visitor)
        self.ctx.progress.complete(name, resume.visitor)
        self.ctx.note(f"resumed: {name} already done")
        return True

    def initialise(self) -> None:
        self.ctx.progress.begin(self.params.checkpoint)

    def update(self) -> Status:
        status = self.decorated.status
        if status == SUCCESS:
            self.ctx.progress.complete(self.params.checkpoint, self.get("/visitor"))
        return status
