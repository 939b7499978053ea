"""What happened, as types: tour states, incident kinds and the reasons a tour ends early.

Nothing in frog-bt learns what happened by reading text: the status line, summaries,
telemetry levels, the executive's exit and the front end's ``tour`` reason all come
from these values. Their words (``.value``) are the ones the contract and the log use.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class TourState(enum.StrEnum):
    """The ``tour`` states sent to the front end (CONTRACT §2)."""

    STARTED = "started"
    ENDED = "ended"
    ABORTED = "aborted"


class Level(enum.StrEnum):
    """How loud a logged thing is (the log's and the viewer's levels)."""

    DEBUG = "DEBUG"
    INFO = "INFO"
    WARN = "WARN"
    ERROR = "ERROR"


class IncidentKind(enum.StrEnum):
    """What went wrong or differently on a tour: summaries and the status line list these;
    each kind has its :attr:`level` (telemetry, the log)."""

    DOCKING_FAILED = "docking failed"
    NAVIGATION_FAILED = "navigation failed"
    STOP_SKIPPED = "stop skipped"  # navigation kept failing: the robot gave the stop up
    STOP_LEFT = "stop left"  # an operator asked to skip it
    APPROACH_FAILED = "approach failed"
    VISITOR_DECLINED = "visitor declined"
    VISITOR_LOST = "visitor lost"
    EVENT_MISSING = "event missing"
    CONTENT_TIMEOUT = "content timeout"
    FRONTEND_RESTARTED = "front end restarted"
    TOUR_ABORTED = "tour aborted"
    GAVE_UP = "gave up"
    RESUMED = "resumed"
    MISSING_VALUE = "missing value"
    STALE_INPUT = "stale input"  # decided without fresh data (benefit of the doubt)
    OPERATOR = "operator"  # an operator command changed the tour

    @property
    def level(self) -> Level:
        return _LEVELS.get(self, Level.WARN)


_LEVELS = {
    IncidentKind.RESUMED: Level.INFO,
    IncidentKind.OPERATOR: Level.INFO,
    IncidentKind.STOP_LEFT: Level.INFO,
    IncidentKind.GAVE_UP: Level.ERROR,
}


class AbortCause(enum.StrEnum):
    """Why a running tour is being ended politely (back to the dock)."""

    BATTERY = "battery"
    FAULT = "electronics fault"
    OPERATOR = "operator"  # sent home from the console or frog-bt ctl


@dataclass(frozen=True, slots=True)
class AbortReason:
    """A polite abort: its cause, and the words the front end and the log get."""

    cause: AbortCause
    text: str  # "battery 12% below 15%"

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True, slots=True)
class Incident:
    """One thing that went wrong or differently, at a project-clock time."""

    at: float
    kind: IncidentKind
    text: str  # plain words: "skipped POI3: navigation kept failing"
    subject: str = ""  # what it is about, where a summary needs it (the POI skipped)


class DockingState(enum.StrEnum):
    """The ``/docking/state`` words (CONTRACT §1): published on each change, repeated."""

    DOCKED = "docked"
    UNDOCKING = "undocking"
    UNDOCKED = "undocked"
    DOCKING = "docking"
    FAILED = "failed"

    @classmethod
    def of(cls, word: str) -> DockingState | None:
        """The state a word means; None for a word the contract does not know."""
        return cls._value2member_map_.get(word)  # type: ignore[return-value]


class DockCommand(enum.StrEnum):
    """What ``/docking/dock`` asks of the robot (CONTRACT §1)."""

    DOCK = "dock"
    UNDOCK = "undock"

    @property
    def busy(self) -> DockingState:
        """The docking state while it is under way."""
        return DockingState.DOCKING if self is DockCommand.DOCK else DockingState.UNDOCKING


class FaceStream(enum.StrEnum):
    """What ``/ICL_command`` asks of the face data stream (CONTRACT §1)."""

    START = "start"
    STOP = "stop"


class DiagnosticLevel(enum.IntEnum):
    """``diagnostic_msgs/DiagnosticStatus`` levels; ERROR and STALE are faults."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3
