"""When the robot cannot go on: it holds where it is and asks a person (CONTRACT §7 ``help``).

A :class:`Help` says what is wrong, since when and which answers a person can give; the
answers are operator commands (``retry``: try the failed step again; ``done_by_hand``: a
person did it, which the executive checks where it can; ``service_off``).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from frog_bt.i18n import N_

__all__ = ["Help", "HelpAbout", "HelpAnswer"]


class HelpAbout(enum.StrEnum):
    """The step that could not be done."""

    UNDOCK = "undock"  # undocking failed after its attempts
    DOCK = "dock"  # docking failed after its attempts
    HOME = "home"  # the robot could not get home to its charger (navigation, docking)
    FAULT = "fault"  # an electronics fault persists with no tour running
    CRASHED = "crashed"  # the executive stopped during a tour: not resumed, to not loop

    @property
    def what(self) -> str:
        """What is wrong, in plain words."""
        return _WHAT[self]

    @property
    def answers(self) -> tuple[str, ...]:
        """The commands a person can give (``done_by_hand``'s check: :attr:`by_hand`)."""
        return ("retry", "done_by_hand", "service_off")

    @property
    def by_hand(self) -> str:
        """What ``done_by_hand`` means, and what the executive checks first."""
        return _BY_HAND[self]


_WHAT = {
    HelpAbout.UNDOCK: N_("The robot could not leave its charger after all its attempts."),
    HelpAbout.DOCK: N_("The robot could not dock after all its attempts."),
    HelpAbout.HOME: N_("The robot could not get back to its charger."),
    HelpAbout.FAULT: N_("The robot reports an electronics fault that does not go away."),
    HelpAbout.CRASHED: N_(
        "The executive stopped during a tour; it did not resume the tour, so as not to stop again."
    ),
}
_BY_HAND = {
    HelpAbout.UNDOCK: N_("a person moved the robot off the charger (the robot reports undocked)"),
    HelpAbout.DOCK: N_("a person put the robot on its charger (the robot reports docked)"),
    HelpAbout.HOME: N_("a person put the robot on its charger (the robot reports docked)"),
    HelpAbout.FAULT: N_("a person fixed the fault (the robot no longer reports it)"),
    HelpAbout.CRASHED: N_("a person put the robot on its charger (the robot reports docked)"),
}


class HelpAnswer(enum.StrEnum):
    RETRY = "retry"
    DONE_BY_HAND = "done_by_hand"


@dataclass(frozen=True, slots=True)
class Help:
    """The robot holds and waits for a person: about what, since when (project clock)."""

    about: HelpAbout
    since: float
    detail: str = ""  # what went wrong, as the executive knows it (crashed: why)

    @property
    def what(self) -> str:
        return self.about.what

    @property
    def answers(self) -> tuple[str, ...]:
        return self.about.answers
