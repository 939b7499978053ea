"""When the robot cannot go on: hold where it is, ask a person, go on with their answer."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from frog_bt.behaviours.registry import register
from frog_bt.behaviours.safety import fresh_diagnostics
from frog_bt.model import keys
from frog_bt.model.help import Help, HelpAbout, HelpAnswer
from frog_bt.model.outcomes import DockingState, IncidentKind
from frog_bt.model.progress import EMPTY
from frog_bt.model.ros import Pose
from frog_bt.tree import leaf
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.world import Channel, Role, World

# What a person's help is about, as the alerts name the incident behind it.
INCIDENT = {
    HelpAbout.UNDOCK: IncidentKind.DOCKING_FAILED,
    HelpAbout.DOCK: IncidentKind.DOCKING_FAILED,
    HelpAbout.HOME: IncidentKind.GAVE_UP,
    HelpAbout.FAULT: IncidentKind.GAVE_UP,
    HelpAbout.CRASHED: IncidentKind.GAVE_UP,
}


@register
class AskForHelp(Leaf):
    """Hold where the robot is and ask a person for help; go on with their answer.

    ``about`` the step that could not be done: ``undock``, ``dock`` or ``home`` ask at
    once (place it after the step, in a selector; ``home`` asks about the docking when
    ``/docking`` says it failed); ``fault`` asks only while fresh
    diagnostics report a fault (SUCCESS at once without one, and once it clears);
    ``restored`` asks only when the executive restored a pending request at start-up
    (``/help_restored``: the robot still waits for a person after a restart; SUCCESS at
    once otherwise).

    Asking: the robot stops driving (a goal at its own pose, if a goal was pending),
    ``/help`` and ``/gave_up`` (the alert's reason) are written and an incident noted.
    Reads ``/help_answer`` (optional: the operator's ``retry`` or ``done_by_hand``, which
    the executive has checked), ``/now``, ``/diagnostics`` and ``/pose`` (optional).
    Writes ``/help``, ``/gave_up``, ``/progress`` (cleared: a restart restores the
    request, not the tour), and takes ``/help_answer`` and ``/help_restored``.
    RUNNING while it waits; SUCCESS on ``done_by_hand`` (a person did the step); FAILURE
    on ``retry`` (the ``Retry`` above it tries the step again).
    """

    class Params(leaf.Params):  # qualified: mypy may take a bare Params for this one
        about: Literal["undock", "dock", "home", "fault", "restored"] = Field(
            description="the step that could not be done (restored: a restart's pending help)"
        )

    params: Params
    reads = (keys.NOW, keys.DIAGNOSTICS)
    optional_reads = (keys.HELP_ANSWER, keys.HELP_RESTORED, keys.POSE, keys.DOCKING)
    writes = (keys.HELP, keys.HELP_ANSWER, keys.HELP_RESTORED, keys.GAVE_UP, keys.PROGRESS)
    world = World(
        inputs=(Channel.OPERATOR, Channel.DIAGNOSTICS, Channel.DOCKING),
        state=("asking",),
        waits=True,
        role=Role.HELP,
    )

    def initialise(self) -> None:
        self.asking: Help | None = None

    def _needed(self) -> HelpAbout | None:
        """What to ask about now, or None when nothing is wrong."""
        about = self.params.about
        if about == "restored":
            restored = self.get(keys.HELP_RESTORED)
            return restored.about if restored is not None else None
        if about == "fault":
            site = self.ctx.site
            diagnostics = fresh_diagnostics(
                self.get(keys.DIAGNOSTICS), self.need(keys.NOW), site.safety.diagnostics_max_age
            )
            return HelpAbout.FAULT if diagnostics is not None and diagnostics.faults else None
        if about == "home":  # home, or the docking at the end of the way home?
            docking = self.get(keys.DOCKING)
            if docking is not None and docking.value == DockingState.FAILED:
                return HelpAbout.DOCK
        return HelpAbout(about)

    def _ask(self, about: HelpAbout) -> None:
        now = self.need(keys.NOW)
        restored = self.get(keys.HELP_RESTORED)
        same = restored is not None and restored.about is about
        since = restored.since if restored is not None and same else now
        self.asking = Help(about, since, restored.detail if restored is not None and same else "")
        self.set(keys.HELP, self.asking)
        self.set(keys.HELP_ANSWER, None)
        actions = self.ctx.actions
        pose = self.get(keys.POSE)
        if actions.pending is not None and pose is not None:
            here = pose.value
            actions.stop(Pose(now, "map", here.x, here.y, here.qz, here.qw))
        detail = f" ({self.asking.detail})" if self.asking.detail else ""
        incident = self.ctx.note(
            f"needs help: {about.what}{detail}", incident=INCIDENT[about], subject=about.value
        )
        self.set(keys.GAVE_UP, incident)
        self.set(keys.PROGRESS, EMPTY)  # a restart restores this request, not the tour
        self.feedback_message = f"waiting for a person: {about.what}"

    def update(self) -> Status:
        about = self._needed()
        if self.asking is None:
            if about is None:
                return SUCCESS
            self._ask(about)
        elif self.params.about == "fault" and about is None:
            self.ctx.note("the fault cleared: going on")
            return SUCCESS
        answer = self.get(keys.HELP_ANSWER)
        if answer is HelpAnswer.DONE_BY_HAND:
            self.ctx.note(f"done by hand: {self.asking.about.by_hand}")  # type: ignore[union-attr]
            return SUCCESS
        if answer is HelpAnswer.RETRY:
            self.ctx.note("a person asked to try again")
            return FAILURE
        return RUNNING

    def terminate(self, new_status: Status) -> None:
        if getattr(self, "asking", None) is not None:
            self.asking = None
            self.set(keys.HELP, None)
            self.set(keys.HELP_ANSWER, None)
            self.set(keys.HELP_RESTORED, None)
            self.set(keys.GAVE_UP, None)
