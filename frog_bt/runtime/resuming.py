"""The one count of tours of a live executive: it carries on the tour the executive resumed.

A :class:`ResumingLedger` is a :class:`~frog_bt.model.ledger.TourLedger` and an
observer. Fed every event, it also looks, after each tick, whether the tree has resumed
a checkpoint's tour (``/resumed`` set, by ``ConfirmResume``); the first time it has, the
tour's row the checkpoint kept (``/resume``'s :attr:`~frog_bt.model.progress.Resume.tour`)
is taken up (:meth:`~frog_bt.model.ledger.TourLedger.resume`): the stops reached and
skipped before the restart, the visitor, the help asked and the staff's commands count
in this executive's tour as the report counts them over both executives' recordings. A
checkpoint the tree dropped (the robot was docked: a fresh tour) is never taken up.

Every live view that counts tours holds one: the executive (its outcome, the journal's
status), the status line, the demo summary, the console's day and shift.
"""

from __future__ import annotations

from typing import cast

from frog_bt.model import keys
from frog_bt.model.events import Event, Ticked
from frog_bt.model.ledger import TourLedger
from frog_bt.runtime.observer import Host

__all__ = ["ResumingLedger"]


class ResumingLedger(TourLedger):
    """A tour ledger attached to ``host`` (:meth:`attach`): see the module."""

    _host: Host | None = None

    def attach(self, host: object) -> None:
        # (typed as the fold's, which keeps nothing: its host is an observer's, a Host)
        self._host = cast("Host", host)

    def on_event(self, event: Event) -> None:
        self.feed(event)
        if isinstance(event, Ticked) and not self.resumed and self._host is not None:
            board = self._host.core.board
            if board.get(keys.RESUMED):
                resume = board.get(keys.RESUME)
                self.resume(resume.tour if resume is not None else None)
