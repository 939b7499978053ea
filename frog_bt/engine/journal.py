"""The decision log: every decision with its reason, and the incidents among them.

A service of the context (:attr:`~frog_bt.engine.context.Context.journal`): leaves
write to it, observers (status line, telemetry, summaries, blame) read it. Incidents are
typed (:class:`~frog_bt.model.outcomes.Incident`); nothing reads the notes' text to
learn what happened.
"""

from __future__ import annotations

from typing import NamedTuple

from frog_bt.clock import Clock
from frog_bt.engine.tally import Tally
from frog_bt.model.outcomes import Incident, IncidentKind, Level


class Note(NamedTuple):
    """One decision: when, in plain words, and the incident it is, if any."""

    at: float
    text: str
    kind: IncidentKind | None = None

    @property
    def level(self) -> Level:
        return self.kind.level if self.kind is not None else Level.INFO


class Journal:
    """Notes and incidents, each list bounded to about ``limit`` entries."""

    def __init__(self, clock: Clock, limit: int = 1000) -> None:
        self._clock = clock
        self.limit = limit
        self.notes: list[Note] = []
        self.incidents: list[Incident] = []
        self.incident_total = 0  # incidents ever recorded (the list keeps the latest)
        self.tally = Tally()  # the one count of incidents

    def note(
        self, text: str, incident: IncidentKind | None = None, subject: str = ""
    ) -> Incident | None:
        """Record a decision and its reason; ``incident`` marks one a summary must list
        (returned)."""
        now = self._clock.now()
        if len(self.notes) >= self.limit:
            del self.notes[: self.limit // 2]
        self.notes.append(Note(now, text, incident))
        if incident is None:
            return None
        if len(self.incidents) >= self.limit:
            del self.incidents[: self.limit // 2]
        record = Incident(now, incident, text, subject)
        self.incidents.append(record)
        self.incident_total += 1
        self.tally.add(record)
        return record

    @property
    def last_note(self) -> str:
        return self.notes[-1].text if self.notes else ""

    def incidents_since(self, seen: int) -> list[Incident]:
        """The incidents recorded after the first ``seen`` of all time (those the list
        still keeps): how a reader takes each once, counting with :attr:`incident_total`."""
        if seen >= self.incident_total:
            return []
        return self.incidents[seen - self.incident_total :]

    def last_incident(self) -> Incident | None:
        return self.incidents[-1] if self.incidents else None
