"""What behaviours reach at run time: clock, site, robot actions, front end, decision log.

Handed to every behaviour through ``BehaviourTree.setup(ctx=...)``; nothing
here exists when a tree is only rendered.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from frog_bt.config import Site
from frog_bt.frontend.messages import FrontendMessage
from frog_bt.kernel.actions import Actions
from frog_bt.kernel.clock import Clock
from frog_bt.runtime.checkpoint import Progress, Resume

# What went wrong or differently on a tour: the summaries and the status line list these.
IncidentKind = Literal[
    "docking failed", "navigation failed", "stop skipped", "approach failed", "visitor declined",
    "visitor lost", "event missing", "content timeout", "front end restarted",
    "tour aborted", "gave up", "resumed", "missing value",
]


@dataclass(frozen=True, slots=True)
class Incident:
    at: float  # project-clock time
    kind: IncidentKind
    text: str  # plain words: "skipped POI3: navigation kept failing"
    subject: str = ""  # what it is about, where a summary needs it (the POI skipped)


@dataclass(slots=True)
class Context:
    clock: Clock
    site: Site
    actions: Actions
    send: Callable[[FrontendMessage], None]
    notes: list[tuple[float, str]] = field(default_factory=list)
    progress: Progress = field(default_factory=Progress)
    resume: Resume | None = None  # set at start-up from a checkpoint file
    resumed: str | None = None  # "resuming the tour at POI4: checkpoint 3 min old"
    incidents: list[Incident] = field(default_factory=list)
    incident_total: int = 0  # incidents ever recorded (the list keeps the latest)
    gave_up: str | None = None  # why the tree gave up (GiveUp): the executive's exit reason
    tour_state: str | None = None  # the latest ``tour`` state sent: started, ended, aborted
    tour_reason: str = ""  # and its reason
    note_limit: int = 1000

    def note(self, text: str, incident: IncidentKind | None = None, subject: str = "") -> None:
        """Record a decision and its reason (the status line, telemetry and logs read these);
        ``incident`` marks one that a summary must list."""
        now = self.clock.now()
        if len(self.notes) >= self.note_limit:
            del self.notes[: self.note_limit // 2]
        self.notes.append((now, text))
        if incident is not None:
            if len(self.incidents) >= self.note_limit:
                del self.incidents[: self.note_limit // 2]
            self.incidents.append(Incident(now, incident, text, subject))
            self.incident_total += 1
