"""What the executive held beside the tree, in a replay: the staff's host, and alerts and
answers as compared and told.

A replay holds the executive's own :class:`~frog_bt.runtime.staff.Staff` (the alert
book, the staff's decisions); :class:`Beside` is its host there: the replayed core and
clock, the links' states as recorded, the replay's observers. An alert change is compared
as :func:`alert_command` (which alert, its state, how often it was told again: its words
are the site's and are not compared); :class:`Said` keeps each alert's latest change on
both sides, so that a divergence about an alert or an operator's answer is told in domain
terms (:meth:`Said.story`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from frog_bt.model.channels import ALERT, OPERATOR, Alert
from frog_bt.recordings.commands import Command, local_time

if TYPE_CHECKING:
    from frog_bt.clock import Clock
    from frog_bt.config import Site
    from frog_bt.engine.core import Core
    from frog_bt.model.events import Event
    from frog_bt.model.links import Links
    from frog_bt.runtime.observer import Observers

__all__ = ["ALERT_BOOK", "STAFF", "Beside", "Said", "alert_command"]

ALERT_BOOK = "the alert book (the executive)"  # who changes alerts: blame's word for it
STAFF = "staff (operator command)"  # who sent an operator command


class Replayed(Protocol):
    """What :class:`Beside` reads of its :class:`~frog_bt.offline.replay.Replay`."""

    @property
    def site(self) -> Site: ...
    @property
    def clock(self) -> Clock: ...
    @property
    def core(self) -> Core: ...
    @property
    def recorded_links(self) -> Links | None: ...
    @property
    def observers(self) -> Observers: ...


class Beside:
    """The replay as the host of its :class:`~frog_bt.runtime.staff.Staff`."""

    def __init__(self, replay: Replayed) -> None:
        self._replay = replay

    @property
    def site(self) -> Site:
        return self._replay.site

    @property
    def clock(self) -> Clock:
        return self._replay.clock

    @property
    def core(self) -> Core:
        return self._replay.core

    @property
    def links(self) -> Links | None:
        return self._replay.recorded_links

    def emit(self, event: Event) -> None:
        if self._replay.observers:
            self._replay.observers.emit(event)

    def wake(self) -> None:
        """Nothing to wake: the recording says when the next tick is."""


def alert_command(t: float, alert: Alert) -> Command:
    """An alert change as compared: which alert, its state, how often told again."""
    payload = {"alert": alert.id, "state": alert.state, "repeat": alert.repeat}
    return Command(t, ALERT, payload, node=ALERT_BOOK)


def _said(payload: dict[str, Any]) -> str:
    """An alert change in words: ``raised``, ``told again (2)``, ``acknowledged``."""
    state, repeat = str(payload.get("state")), payload.get("repeat", 0)
    return f"told again ({repeat})" if state == "raised" and repeat else state


def _hms(t: float) -> str:
    """``10:14:07``, at the site."""
    return local_time(t)[11:19]


def _answer(payload: dict[str, Any]) -> str:
    return f"{'applied' if payload.get('ok') else 'refused'} ({payload.get('did', '')})"


@dataclass(slots=True)
class Said:
    """Each alert's latest change on each side (id -> (words, when))."""

    sides: dict[str, dict[str, tuple[str, float]]] = field(
        default_factory=lambda: {"recording": {}, "replay": {}}
    )

    def recorded(self, t: float, alert: Alert) -> None:
        self.sides["recording"][alert.id] = (_said(alert_command(t, alert).payload), t)

    def replayed(self, t: float, alert: Alert) -> None:
        self.sides["replay"][alert.id] = (_said(alert_command(t, alert).payload), t)

    def story(self, expected: Command | None, got: Command | None) -> str:
        """A divergence about an alert or an operator's answer in domain terms (``the
        alert docking_failed was acknowledged at 10:14:07 in the recording; in the replay
        it was never raised``); empty for any other."""
        for where, other, this, that in (
            ("recording", "replay", expected, got),
            ("replay", "recording", got, expected),
        ):
            if this is not None and this.channel == ALERT:
                return self._alert(where, other, this, that)
        if expected is not None and got is not None and expected.channel == got.channel == OPERATOR:
            a = expected.payload
            what = a["command"] + (f" {a['id']}" if a.get("id") else "")
            return (
                f"the operator's {what} at {_hms(expected.t)} was {_answer(a)} in the "
                f"recording; in the replay it was {_answer(got.payload)}"
            )
        for where, this in (("recording", expected), ("replay", got)):
            if this is not None and this.channel == OPERATOR:
                p = this.payload
                return (
                    f"the operator's {p['command']} at {_hms(this.t)} was {_answer(p)} "
                    f"in the {where} only"
                )
        return ""

    def _alert(self, where: str, other: str, this: Command, that: Command | None) -> str:
        alert_id = this.payload["alert"]
        said = f"the alert {alert_id} was {_said(this.payload)} at {_hms(this.t)} in the {where}"
        if that is not None and that.channel == ALERT:
            if that.payload["alert"] == alert_id:
                return f"{said}; in the {other} it was {_said(that.payload)}"
            return (
                f"{said}; in the {other} the alert {that.payload['alert']} was "
                f"{_said(that.payload)} at {_hms(that.t)} instead"
            )
        seen = self.sides[other].get(alert_id)
        if seen is None:
            return f"{said}; in the {other} it was never raised"
        words, at = seen
        return f"{said}; in the {other} it was {words} at {_hms(at)}, and nothing since"
