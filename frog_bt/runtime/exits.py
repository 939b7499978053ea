"""When a run ends: the exit rules, kept out of the executive (which only runs).

``frog-bt run`` (and a rehearsal: ``frog-bt demo``, the tests) attaches :class:`ExitRules`
to its executive. After each tick (:class:`~frog_bt.model.events.Ticked`) it reads the
root's status and the board, and stops the executive (``Executive.stop``) with the exit
code and the one-line reason CONTRACT §5 asks for:

* the tree failed (it gave up: the robot cannot go on): exit 1 with the give-up's text,
  always;
* with ``once``: a tour ended docked: exit 0; a tour aborted: exit 1 with its reason; the
  robot asks for help: exit 1, ``needs help: ...`` (without ``once`` it holds and waits
  for a person, CONTRACT §7);
* with ``once``: rosbridge refused the authentication three times in a row: exit 1.

It counts the tours it saw end (:attr:`ExitRules.tours`) and sets the run's
:attr:`~frog_bt.runtime.executive.Outcome.tours` from the one count of tours (the
executive's ledger).
"""

from __future__ import annotations

import logging

from frog_bt.model import keys
from frog_bt.model.events import Event, Ticked
from frog_bt.model.outcomes import TourState
from frog_bt.rosbridge.link import LinkState
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.observer import Host

__all__ = ["REFUSALS", "ExitRules"]

log = logging.getLogger(__name__)
REFUSALS = 3  # connections refused in a row (authentication) before --once gives up


class ExitRules:
    """The exit rules of one run (``once``: one tour, then exit); see the module."""

    def __init__(self, once: bool = False) -> None:
        self.once = once
        self.tours = 0  # completed (ended, not aborted)
        self._refusals = 0  # consecutive connections refused (auth)
        self._host: Executive | None = None

    def attach(self, host: Host) -> None:
        if not isinstance(host, Executive):
            raise TypeError(f"exit rules stop an executive, not a {type(host).__name__}")
        self._host = host
        host.link_listeners.append(self.on_link)

    def close(self) -> None:
        """Nothing to finish."""

    def on_link(self, state: LinkState) -> None:
        """The robot's link changed: three refusals in a row end a ``once`` run (a refused
        connection goes up, then down at once: only a loss that was no refusal resets)."""
        if state.connected:
            return
        self._refusals = self._refusals + 1 if state.refused else 0
        if self._refusals >= REFUSALS and self.once and self._host is not None:
            self._host.stop("rosbridge refused authentication (check the secret)", 1)

    def on_event(self, event: Event) -> None:
        if isinstance(event, Ticked) and self._host is not None:
            self.ticked(self._host, event.status)

    def ticked(self, host: Executive, status: str) -> None:
        board = host.core.board
        help_ = board.get(keys.HELP)
        if help_ is not None and self.once:  # CONTRACT §5: --once exits with the reason
            host.stop(f"needs help: {help_.what}", 1)
        elif status == "SUCCESS":
            if board.get(keys.TOUR_STATE) is TourState.ABORTED:
                reason = f"tour aborted: {board.get(keys.TOUR_REASON) or 'no reason given'}"
                log.warning("%s", reason)
                if self.once:
                    host.stop(reason, 1)
                return
            self.tours += 1
            host.outcome.tours = host.ledger.completed  # the one count of tours
            if self.once:
                host.stop("tour ended docked", 0)
        elif status == "FAILURE":
            # the tree gave up (GiveUp told the front end): the robot cannot go on
            gave_up = board.get(keys.GAVE_UP)
            reason = gave_up.text if gave_up is not None else "the tour tree failed"
            log.error("cannot go on: %s", reason)
            host.stop(reason, 1)
