"""Operator commands (CONTRACT §7): checked, applied to the board at a tick boundary, answered.

The console and ``frog-bt ctl`` queue commands; the executive hands each to
:meth:`Operator.apply` just before a tick (and replay does the same at the recorded tick),
so a command enters the tree as an input, like any other. The tree files decide what it
does: ``MustAbort`` reads ``/home`` (the same polite abort as a low battery),
``OperatorSkip`` around each stop reads ``/skip``, ``Navigate`` and ``PlayContent`` hold
while ``/paused``, ``WaitInService`` keeps the robot docked while out of service.

Each command is answered with what it did, or refused with why (a ``skip`` while
docked); nothing is half-applied: a refused command changes nothing. A pause longer
than ``pause_max`` seconds of project-clock time ends the tour politely
(:meth:`Operator.check_pause`).
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from frog_bt.engine.blackboard import Board
from frog_bt.engine.standing import Standing
from frog_bt.i18n import N_, Msg
from frog_bt.model import keys
from frog_bt.model.help import Help, HelpAbout, HelpAnswer
from frog_bt.model.outcomes import (
    AbortCause,
    AbortReason,
    DockingState,
    IncidentKind,
    TourState,
)


class Command(enum.StrEnum):
    HOME = "home"
    SKIP = "skip"
    PAUSE = "pause"
    RESUME = "resume"
    SERVICE_OFF = "service_off"
    SERVICE_ON = "service_on"
    ACK_ALERT = "ack_alert"  # the alerts' business, not the tree's (the executive answers it)
    RETRY = "retry"  # the robot needs help: try the failed step again
    DONE_BY_HAND = "done_by_hand"  # the robot needs help: a person did the step


# the step ``retry`` tries again, in words (``trying again: dock``)
_STEP = {
    HelpAbout.UNDOCK: N_("undock"),
    HelpAbout.DOCK: N_("dock"),
    HelpAbout.HOME: N_("home"),
    HelpAbout.FAULT: N_("fault"),
    HelpAbout.CRASHED: N_("home"),
}
# /docking/state in words staff use (a refusal never quotes the robot's codes)
DOCKING_WORDS = {
    "docked": N_("on its charger"),
    "undocked": N_("off its charger"),
    "docking": N_("docking"),
    "undocking": N_("leaving its charger"),
    "failed": N_("stuck after a failed docking"),
    "nothing": N_("silent about its charger"),
}
TREE_COMMANDS = frozenset(Command) - {Command.ACK_ALERT}
SENT_HOME = AbortReason(AbortCause.OPERATOR, "operator")


@dataclass(frozen=True, slots=True)
class Answer:
    """``ok``: applied, and ``words`` say what it did; else ``words`` say why not (a
    :class:`~frog_bt.i18n.Msg`, shown in the reader's language; ``text`` is the English
    sentence that is logged and recorded)."""

    ok: bool
    words: Msg | str

    @property
    def text(self) -> str:
        return str(self.words)


class Operator:
    """The tree's side of operator commands, for one core.

    ``stops`` gives the stops the tree is at or driving to now (the running
    ``OperatorSkip`` nodes' POIs, innermost last)."""

    def __init__(
        self, board: Board, standing: Standing, stops: Callable[[], Iterable[str]], pause_max: float
    ) -> None:
        self.board = board
        self.standing = standing  # the pause timer and the journal outlive this tree
        self.journal = standing.journal
        self.stops = stops
        self.pause_max = pause_max
        if not board.written(keys.PAUSED):
            board.set(keys.PAUSED, False)
        if not board.written(keys.IN_SERVICE):
            board.set(keys.IN_SERVICE, True)

    @property
    def paused_since(self) -> float | None:
        return self.standing.paused_since

    def _touring(self) -> bool:
        return self.board.get(keys.TOUR_STATE) is TourState.STARTED

    def apply(self, command: Command, now: float) -> Answer:
        """Check ``command`` against the tour now and apply it to the board."""
        answer = self._decide(command, now)
        if answer.ok:
            self.journal.note(
                f"operator: {command}: {answer.text}", IncidentKind.OPERATOR, subject=command.value
            )
        return answer

    def _decide(self, command: Command, now: float) -> Answer:
        board = self.board
        if command is Command.HOME:
            if not self._touring():
                return Answer(
                    False, Msg("no tour is running: the robot is at the dock or going there")
                )
            if board.get(keys.HOME) is not None or board.get(keys.ABORT_REASON) is not None:
                return Answer(False, Msg("the tour is already ending: the robot is going home"))
            board.set(keys.HOME, SENT_HOME)
            self._unpause()
            return Answer(True, Msg("ending the tour: the robot goes home and docks"))
        if command is Command.SKIP:
            stops = list(self.stops())
            if not self._touring() or not stops:
                return Answer(False, Msg("not at a stop or driving to one: nothing to skip"))
            if board.get(keys.HOME) is not None or board.get(keys.ABORT_REASON) is not None:
                return Answer(False, Msg("the tour is ending: nothing to skip"))
            board.set(keys.SKIP, (board.get(keys.SKIP) or 0) + 1)
            return Answer(True, Msg("skipping {stop}: on to the next stop", stop=stops[-1]))
        if command is Command.PAUSE:
            if board.get(keys.PAUSED):
                return Answer(False, Msg("already paused"))
            if not self._touring():
                return Answer(False, Msg("no tour is running (service_off keeps the robot docked)"))
            board.set(keys.PAUSED, True)
            self.standing.paused_since = now
            return Answer(
                True,
                Msg(
                    "pausing at the next step (at most {seconds} s, then the tour ends)",
                    seconds=f"{self.pause_max:g}",
                ),
            )
        if command is Command.RESUME:
            if not board.get(keys.PAUSED):
                return Answer(False, Msg("not paused"))
            self._unpause()
            return Answer(True, Msg("resuming the tour"))
        if command is Command.SERVICE_OFF:
            if not board.get(keys.IN_SERVICE):
                return Answer(False, Msg("already out of service"))
            board.set(keys.IN_SERVICE, False)
            return Answer(
                True,
                Msg("out of service: this tour finishes, then no new tour starts")
                if self._touring()
                else Msg("out of service: no new tour starts"),
            )
        if command is Command.SERVICE_ON:
            if board.get(keys.IN_SERVICE):
                return Answer(False, Msg("already in service"))
            board.set(keys.IN_SERVICE, True)
            return Answer(True, Msg("in service: tours start again"))
        if command in (Command.RETRY, Command.DONE_BY_HAND):
            return self._answer_help(command)
        return Answer(False, Msg("{command} is not a tree command", command=command.value))

    def _answer_help(self, command: Command) -> Answer:
        """``retry`` or ``done_by_hand`` while the robot waits for a person; the node that
        asked takes the answer at the next tick. ``done_by_hand`` is checked first against
        what the robot reports (docked, undocked, no fault)."""
        board = self.board
        help_ = board.get(keys.HELP)
        if help_ is None:
            return Answer(False, Msg("the robot does not need help now"))
        if board.get(keys.HELP_ANSWER) is not None:
            return Answer(False, Msg("an answer is already being acted on"))
        if command is Command.RETRY:
            board.set(keys.HELP_ANSWER, HelpAnswer.RETRY)
            return Answer(True, Msg("trying again: {step}", step=Msg(_STEP[help_.about])))
        refusal = self.not_done(help_)
        if refusal is not None:
            return Answer(False, refusal)
        board.set(keys.HELP_ANSWER, HelpAnswer.DONE_BY_HAND)
        return Answer(True, Msg("going on: {done}", done=Msg(help_.about.by_hand)))

    def not_done(self, help_: Help) -> Msg | None:
        """Why ``done_by_hand`` cannot be true yet, from what the robot reports; None."""
        about = help_.about
        if about in (HelpAbout.DOCK, HelpAbout.HOME, HelpAbout.UNDOCK, HelpAbout.CRASHED):
            want = DockingState.UNDOCKED if about is HelpAbout.UNDOCK else DockingState.DOCKED
            reading = self.board.get(keys.DOCKING)
            state = reading.value if reading is not None else "nothing"
            if state != want:
                return Msg(
                    "the robot says it is {state}, not {want}: finish the step, then answer again",
                    state=Msg(DOCKING_WORDS.get(str(state), N_("in a state it does not name"))),
                    want=Msg(DOCKING_WORDS[want.value]),
                )
        if about is HelpAbout.FAULT:
            diagnostics = self.board.get(keys.DIAGNOSTICS)
            if diagnostics is not None and diagnostics.value.faults:
                return Msg(
                    "the robot still reports a fault: {faults}",
                    faults="; ".join(diagnostics.value.faults),
                )
        return None

    def _unpause(self) -> None:
        self.board.set(keys.PAUSED, False)
        self.standing.paused_since = None

    def check_pause(self, now: float) -> AbortReason | None:
        """Before each tick: a pause that ran out ends the tour politely (its reason). A
        pause restored after a restart counts from the first tick that sees it."""
        if self.paused_since is None and self.board.get(keys.PAUSED):
            self.standing.paused_since = now
        if self.paused_since is None or now - self.paused_since < self.pause_max:
            return None
        self._unpause()
        if not self._touring():
            return None
        reason = AbortReason(AbortCause.OPERATOR, f"paused longer than {self.pause_max:g} s")
        if self.board.get(keys.HOME) is None and self.board.get(keys.ABORT_REASON) is None:
            self.board.set(keys.HOME, reason)
        self.journal.note(
            f"pause ran out after {self.pause_max:g} s: ending the tour",
            IncidentKind.OPERATOR,
            subject="pause",
        )
        return reason
