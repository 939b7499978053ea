"""What behaviours reach at run time: services, not data.

Handed to every node through ``setup(ctx=...)``; nothing here exists when a tree is only
rendered. The tour's values live on the blackboard (:mod:`frog_bt.model.keys`); the
context carries only what does things: the clock, the site, the robot's actions, the
front end's send, and the decision log.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from frog_bt.clock import Clock
from frog_bt.config import Site
from frog_bt.engine.actions import Actions
from frog_bt.engine.faults import Faults
from frog_bt.engine.journal import Journal
from frog_bt.model.frontend import FrontendMessage
from frog_bt.model.outcomes import Incident, IncidentKind

__all__ = ["Context", "Incident", "IncidentKind"]


@dataclass(frozen=True, slots=True)
class Context:
    clock: Clock
    site: Site
    actions: Actions
    send: Callable[[FrontendMessage], None]
    journal: Journal
    faults: Faults | None = None  # where a node's failure of its own code is counted

    def note(
        self, text: str, incident: IncidentKind | None = None, subject: str = ""
    ) -> Incident | None:
        """Record a decision and its reason in the journal (see :meth:`Journal.note`)."""
        return self.journal.note(text, incident, subject)
