"""Why tours went less than well: one typed taxonomy, each event counted once.

An :class:`Incident` is one event of a tour with its :class:`Cause` and a detail (the
stop, the fault's name, the alert's kind). What follows from an event already counted
is not counted again: the abort a fault or the operator's ``home`` caused, the
``fault`` alert of a fault the diagnostics reported, the ``stop_given_up`` alert of a
stop given up, the stops a restart left unrecorded.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class Cause(enum.StrEnum):
    NAV_RETRY = "navigation retry"  # a goal sent again after it failed (detail: stop)
    STOP_GIVEN_UP = "stop given up"  # navigation kept failing: skipped (detail: stop)
    APPROACH_REJECTED = "approach rejected"  # /ApproachPeopleFar answered 3/4
    INVITATION_DECLINED = "invitation declined"  # the person said no
    VISITOR_LOST = "visitor lost"  # no longer followed: a new visitor recruited
    DOCK_RETRY = "dock retry"  # dock or undock sent again after it failed
    FAULT = "fault"  # a /diagnostic ERROR (detail: its name)
    HELP_NEEDED = "help needed"  # the robot held and asked a person (detail: alert kind)
    ALERT = "alert"  # any other alert (detail: its kind)
    OPERATOR = "operator"  # a person changed the tour (detail: home, skip)
    RESTART = "restart"  # an executive started again and resumed the tour
    ABORTED = "aborted"  # aborted with no event above to explain it (detail: reason)
    CUT = "recording ends mid-tour"


@dataclass(frozen=True)
class Incident:
    cause: Cause
    detail: str = ""

    def __str__(self) -> str:
        return f"{self.cause.value}: {self.detail}" if self.detail else self.cause.value
