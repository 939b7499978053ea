"""Never strand a visitor or the robot: abort politely, give up cleanly, resume after a restart."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import py_trees
from pydantic import Field

from frog_bt.behaviours.registry import register, register_decorator
from frog_bt.model import keys
from frog_bt.model.frontend import Tour
from frog_bt.model.key import Reading
from frog_bt.model.outcomes import (
    AbortCause,
    AbortReason,
    DockingState,
    Incident,
    IncidentKind,
    TourState,
)
from frog_bt.model.progress import EMPTY, Progress
from frog_bt.model.ros import Diagnostics
from frog_bt.text import LINE, inert
from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status
from frog_bt.tree.world import Channel, World

log = logging.getLogger(__name__)


def fresh_diagnostics(
    reading: Reading[Diagnostics] | None, now: float, max_age: float
) -> Diagnostics | None:
    """The diagnostics if recent enough to act on, else None (stale data is not acted on)."""
    if reading is None or reading.age(now) > max_age:
        return None
    return reading.value


@register
class MustAbort(Leaf):
    """Must the tour be aborted? (an operator sent the robot home, battery low or an
    electronics fault, during a tour)

    Reads ``/home`` (optional: the operator's request, with its reason), ``/diagnostics``
    (only when fresher than ``safety.diagnostics_max_age``), ``/now``, ``/tour_state``
    (optional) and ``/abort_reason`` (optional). Writes ``/abort_reason`` (an
    :class:`~frog_bt.model.outcomes.AbortReason`). SUCCESS while an abort is under way
    (the reason is latched until :class:`ClearAbort`); FAILURE otherwise.
    """

    reads = (keys.DIAGNOSTICS, keys.NOW)
    optional_reads = (keys.TOUR_STATE, keys.ABORT_REASON, keys.HOME)
    writes = (keys.ABORT_REASON,)
    world = World(
        inputs=(Channel.DIAGNOSTICS, Channel.OPERATOR),
        truthy=(keys.ABORT_REASON.name, keys.HOME.name),
        diagnostics=("ok", "battery low"),
        why="battery: low (below safety.battery_low) or full; a fault or none: both abort "
        "alike (the reason's words differ). Of /home "
        "it decides on whether it is set; its words become the abort's, which only the "
        "front end reads",
    )

    def update(self) -> Status:
        if self.get(keys.ABORT_REASON) is not None:
            return SUCCESS
        if self.get(keys.TOUR_STATE) is not TourState.STARTED:
            return FAILURE
        home = self.get(keys.HOME)
        if home is not None:
            self.set(keys.ABORT_REASON, home)
            self.ctx.note(f"abort the tour: {home.text}", incident=IncidentKind.TOUR_ABORTED)
            return SUCCESS
        cfg = self.ctx.site.safety
        diagnostics = fresh_diagnostics(
            self.get(keys.DIAGNOSTICS), self.need(keys.NOW), cfg.diagnostics_max_age
        )
        if diagnostics is None:
            self.feedback_message = "diagnostics stale or missing: not acted on"
            return FAILURE
        reason: AbortReason | None = None
        if diagnostics.faults:
            reason = AbortReason(  # each fault is inert already; the whole is bounded too
                AbortCause.FAULT, inert("electronics fault: " + "; ".join(diagnostics.faults), LINE)
            )
        elif diagnostics.battery is not None and diagnostics.battery < cfg.battery_low:
            reason = AbortReason(
                AbortCause.BATTERY, f"battery {diagnostics.battery:.0f}% below {cfg.battery_low:g}%"
            )
        if reason is None:
            self.feedback_message = ""
            return FAILURE
        self.set(keys.ABORT_REASON, reason)
        self.ctx.note(f"abort the tour: {reason.text}", incident=IncidentKind.TOUR_ABORTED)
        return SUCCESS


@register
class ClearAbort(Leaf):
    """The abort is done: clear ``/abort_reason`` (kept as ``/abort_reason_last``) and the
    operator's ``/home`` request. SUCCESS."""

    optional_reads = (keys.ABORT_REASON,)
    writes = (keys.ABORT_REASON, keys.ABORT_REASON_LAST, keys.HOME)
    world = World(
        ignores=(keys.ABORT_REASON.name,), why="it keeps the reason as /abort_reason_last"
    )

    def update(self) -> Status:
        self.set(keys.ABORT_REASON_LAST, self.get(keys.ABORT_REASON))
        self.set(keys.ABORT_REASON, None)
        self.set(keys.HOME, None)
        return SUCCESS


@register
class GiveUp(Leaf):
    """The tour cannot go on: tell the front end why (``tour aborted``) and fail.

    The reason is the latest incident of the journal (e.g. ``undock failed``, a docking
    failure), a typed value. Writes ``/tour_state``, ``/tour_reason``, ``/progress``
    (cleared) and ``/gave_up`` (the incident: the executive stops with its words).
    FAILURE, always.
    """

    writes = (keys.TOUR_STATE, keys.TOUR_REASON, keys.PROGRESS, keys.GAVE_UP)
    world = World()

    def update(self) -> Status:
        cause = self.ctx.journal.last_incident()
        if cause is None:
            cause = Incident(self.ctx.clock.now(), IncidentKind.GAVE_UP, "the tour cannot go on")
        reason = cause.text
        self.ctx.send(Tour(TourState.ABORTED, reason))
        self.set(keys.TOUR_STATE, TourState.ABORTED)
        self.set(keys.TOUR_REASON, reason)
        self.set(keys.PROGRESS, EMPTY)
        self.set(keys.GAVE_UP, cause)
        self.ctx.note(f"giving up: {reason}", incident=IncidentKind.GAVE_UP)
        self.feedback_message = reason
        return FAILURE


@register
class ConfirmResume(Leaf):
    """Decide whether to resume the tour of a checkpoint left by a previous run.

    Only a robot that reports itself away from the dock (``/docking`` not
    ``docked``) within ``checkpoint.confirm`` seconds resumes; otherwise the
    checkpoint is dropped (``/resume`` and ``/progress`` cleared) and a fresh tour
    starts. A resumed tour is a started tour (``/tour_state`` ``started``, as the
    executive before told the front end): an abort, the operator's ``home`` and the
    recording's rotation see it as one. Reads ``/docking``, ``/now``, ``/resume``;
    writes ``/resumed`` (how, in words) and ``/tour_state``. SUCCESS once decided (at
    once without a checkpoint).
    """

    reads = (keys.DOCKING, keys.NOW)
    optional_reads = (keys.RESUME,)
    writes = (keys.RESUME, keys.RESUMED, keys.PROGRESS, keys.TOUR_STATE)
    world = World(
        inputs=(Channel.DOCKING, Channel.CLOCK),
        state=("started",),
        times=("started",),
        timer=lambda n: n.started + n.ctx.site.checkpoint.confirm,
        views=((keys.RESUME.name, lambda r: True),),
        why="of a checkpoint it decides only on whether there is one: the rest (where, how "
        "old) is the words it announces",
    )

    def initialise(self) -> None:
        self.started = self.ctx.clock.now()

    def update(self) -> Status:
        resume = self.get(keys.RESUME)
        if resume is None:
            return SUCCESS
        state = self.get(keys.DOCKING)
        if state is not None and state.value not in (DockingState.DOCKED, DockingState.DOCKING):
            announce = resume.announce([stop.poi for stop in self.ctx.site.tour.stops])
            self.set(keys.RESUMED, announce)
            self.set(keys.TOUR_STATE, TourState.STARTED)  # no new `tour started` is sent
            self.ctx.note(f"{announce} ({resume.describe()})", incident=IncidentKind.RESUMED)
            log.warning("%s", announce)
            return SUCCESS
        confirm = self.ctx.site.checkpoint.confirm
        if state is not None or self.need(keys.NOW) - self.started >= confirm:
            why = f"the robot is {state.value}" if state else "no docking state"
            self.ctx.note(f"checkpoint dropped ({why}): a fresh tour")
            self.set(keys.RESUME, None)
            self.set(keys.PROGRESS, EMPTY)
            return SUCCESS
        self.feedback_message = "checkpoint found: waiting for the docking state"
        return RUNNING


@register_decorator
class Checkpointed(FrogDecorator):
    """A part of the tour recorded in the checkpoint as ``checkpoint`` when it succeeds.

    A tour resumed from a checkpoint skips it (SUCCESS without running the
    child) when the checkpoint says it was done, restoring ``/visitor``.
    Running it again drops it and every later checkpoint from ``/progress``.
    Reads ``/visitor``, ``/resume``, ``/progress`` (optional); writes ``/visitor``,
    ``/resume`` (the part skipped, once) and ``/progress``. Returns the child's status.
    """

    class Params(Params):
        checkpoint: str = Field(
            min_length=1, description=("the part's name in the checkpoint (unique in the tree)")
        )

    params: Params
    optional_reads = (keys.VISITOR, keys.RESUME, keys.PROGRESS)
    writes = (keys.VISITOR, keys.RESUME, keys.PROGRESS)
    skips_child = True  # resumed: SUCCESS without the child (the data-flow check)
    _skip = False
    world = World(
        state=("_skip",),
        late=(keys.VISITOR.name,),
        passes=True,
        people=(keys.VISITOR.name, keys.RESUME.name, keys.PROGRESS.name),
        views=((keys.RESUME.name, lambda r: (r.done, r.visitor if r.done else None)),),
        why="of a checkpoint to resume it reads what is still to skip and the visitor a "
        "skip restores; the rest is words",
    )

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        # Resumed past this part: py_trees' plain behaviour tick (initialise, update,
        # stop) instead of the decorator's, which would tick the child.
        self._skip = self.status != RUNNING and self._resumed_past()
        if self._skip:
            yield from py_trees.behaviour.Behaviour.tick(self)
        else:
            yield from super().tick()

    def _progress(self) -> Progress:
        return self.get(keys.PROGRESS) or EMPTY

    def _resumed_past(self) -> bool:
        resume, name = self.get(keys.RESUME), self.params.checkpoint
        if resume is None or name not in resume.done:
            return False
        self.set(keys.RESUME, resume.without(name))
        if resume.visitor is not None:
            self.set(keys.VISITOR, resume.visitor)
        self.set(keys.PROGRESS, self._progress().complete(name, resume.visitor))
        self.ctx.note(f"resumed: {name} already done")
        return True

    def initialise(self) -> None:
        if not self._skip:
            self.set(keys.PROGRESS, self._progress().begin(self.params.checkpoint))

    def update(self) -> Status:
        if self._skip:
            return SUCCESS
        status = self.decorated.status
        if status == SUCCESS:
            self.set(
                keys.PROGRESS,
                self._progress().complete(self.params.checkpoint, self.get(keys.VISITOR)),
            )
        return status
