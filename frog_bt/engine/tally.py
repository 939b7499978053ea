"""One tally of incidents, for everyone who reports them: the tour summary, the console's
day and the alerts read this one count instead of keeping their own.

The journal (:class:`~frog_bt.engine.journal.Journal`) adds every incident it records; the
core starts a new tour's part when it tells the front end ``tour started``.
"""

from __future__ import annotations

from collections import Counter

from frog_bt.model.outcomes import Incident, IncidentKind

__all__ = ["Tally"]

LEFT_STOPS = (IncidentKind.STOP_SKIPPED, IncidentKind.STOP_LEFT)


class Tally:
    """Incidents by kind since the executive started, and the latest tour's in order."""

    def __init__(self) -> None:
        self.by_kind: Counter[IncidentKind] = Counter()
        self.tour: list[Incident] = []  # since the latest tour started (kept after it ends)

    def add(self, incident: Incident) -> None:
        self.by_kind[incident.kind] += 1
        self.tour.append(incident)

    def take_up(self, tour: list[Incident]) -> None:
        """The latest tour's incidents, as another tally held them (a replay of a rotated
        recording file)."""
        self.tour = list(tour)

    def tour_started(self) -> None:
        self.tour = []

    def stops_left(self) -> list[str]:
        """The latest tour's stops skipped or left (skip, lost visitor), in order."""
        return [i.subject for i in self.tour if i.kind in LEFT_STOPS]

    def stops_given_up(self) -> list[str]:
        """The latest tour's stops given up because navigation kept failing."""
        return [i.subject for i in self.tour if i.kind is IncidentKind.STOP_SKIPPED]

    def count(self, *kinds: IncidentKind) -> int:
        """Incidents of these kinds since the executive started."""
        return sum(self.by_kind[k] for k in kinds)
