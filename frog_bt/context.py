"""What behaviours reach at run time: clock, site, robot actions, front end, decision log.

Handed to every behaviour through ``BehaviourTree.setup(ctx=...)``; nothing
here exists when a tree is only rendered.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from frog_bt.actions import Actions
from frog_bt.checkpoint import Progress, Resume
from frog_bt.clock import Clock
from frog_bt.config import Site
from frog_bt.frontend.messages import FrontendMessage


@dataclass(slots=True)
class Context:
    clock: Clock
    site: Site
    actions: Actions
    send: Callable[[FrontendMessage], None]
    notes: list[tuple[float, str]] = field(default_factory=list)
    progress: Progress = field(default_factory=Progress)
    resume: Resume | None = None  # set at start-up from a checkpoint file
    note_limit: int = 1000

    def note(self, text: str) -> None:
        """Record a decision and its reason (the status line, telemetry and logs read these)."""
        if len(self.notes) >= self.note_limit:
            del self.notes[: self.note_limit // 2]
        self.notes.append((self.clock.now(), text))
