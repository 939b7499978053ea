"""The robot asks for help: alerts raised once, cleared when their condition ends,
acknowledged by a person.

:func:`conditions` looks at one moment of the executive (a :class:`Facts`, pure data on
the project clock) and says which conditions hold now, each with one plain sentence and
what to do. :class:`AlertBook` turns that into changes: an alert is raised the first
time its condition holds, cleared when it no longer does (a one-off, such as a stop given
up, holds until the tour ends), and acknowledged by ``ack_alert``. Every change goes to
the book's listeners: the log and status line, the recording, the console and the
webhooks (:mod:`frog_bt.live.console.webhooks`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

from frog_bt.config import AlertsCfg
from frog_bt.model.channels import Alert

log = logging.getLogger("frog_bt.alerts")


@dataclass(frozen=True, slots=True)
class Facts:
    """What the alert conditions look at, at one moment (project-clock seconds)."""

    now: float
    battery: float | None = None  # percent, from fresh diagnostics
    faults: tuple[str, ...] = ()  # from fresh diagnostics
    rosbridge_down_since: float | None = None  # None while connected
    frontend_silent_since: float | None = None  # None while it answers
    seeking_since: float | None = None  # the search for a visitor has run since
    gave_up: str = ""  # the tree gave up: why (docking failed after its attempts, ...)
    docking_gave_up: bool = False  # ... and it was the docking
    stops_given_up: tuple[str, ...] = ()  # stops skipped this tour (navigation kept failing)
    pause_ran_out: bool = False  # this tour: a pause ended it


@dataclass(frozen=True, slots=True)
class Condition:
    kind: str  # docking_failed, stop_given_up, fault, battery_low, rosbridge_down, ...
    subject: str  # what it is about (the stop), "" when the kind says it all
    text: str  # one plain sentence, then what to do

    @property
    def id(self) -> str:
        return f"{self.kind}:{self.subject}" if self.subject else self.kind


def conditions(f: Facts, cfg: AlertsCfg) -> list[Condition]:
    """The conditions that hold now, in the order a person should read them."""
    out: list[Condition] = []
    if f.docking_gave_up:
        out.append(Condition("docking_failed", "", "The robot could not dock after all its "
                             "attempts. Guide it onto the charger by hand and restart it."))
    elif f.gave_up:
        out.append(Condition("gave_up", "", f"The robot stopped the tour: {f.gave_up}. "
                             "Check it, then restart it."))
    for stop in f.stops_given_up:
        out.append(Condition("stop_given_up", stop, f"The robot could not reach {stop} and "
                             "skipped it. Check that the way there is clear."))
    if f.faults:
        out.append(Condition("fault", "", "The robot reports an electronics fault: "
                             f"{'; '.join(f.faults)}. Call the robot team."))
    if f.battery is not None and f.battery < cfg.battery_below:
        out.append(Condition("battery_low", "", f"The battery is at {f.battery:.0f}%. Make "
                             "sure the robot can reach its charger."))
    if (f.rosbridge_down_since is not None
            and f.now - f.rosbridge_down_since >= cfg.rosbridge_down_after):
        out.append(Condition("rosbridge_down", "", "The executive cannot reach the robot "
                             f"(rosbridge) for {f.now - f.rosbridge_down_since:.0f} s. "
                             "Check that the robot is on and on the network."))
    if (f.frontend_silent_since is not None
            and f.now - f.frontend_silent_since >= cfg.frontend_silent_after):
        out.append(Condition("frontend_silent", "", "The screen and sound (front end) do "
                             f"not answer for {f.now - f.frontend_silent_since:.0f} s. "
                             "Restart the front end."))
    if f.seeking_since is not None and f.now - f.seeking_since >= cfg.no_visitor_after:
        out.append(Condition("no_visitor", "", "No visitor has been found for "
                             f"{(f.now - f.seeking_since) / 60:.0f} min. Check that the "
                             "robot stands where visitors pass and that its camera sees."))
    if f.pause_ran_out:
        out.append(Condition("pause_ran_out", "", "The tour was paused too long and ended. "
                             "The robot is going back to its dock."))
    return out


Listener = Callable[[float, Alert], None]


@dataclass
class AlertBook:
    """The alerts now: raised once per condition, cleared when it ends, acknowledged by a
    person. An alert stays shown (raised or cleared) until acknowledged."""

    cfg: AlertsCfg
    listeners: list[Listener] = field(default_factory=list)
    active: dict[str, Alert] = field(default_factory=dict)  # id -> raised, not cleared
    unacknowledged: dict[str, Alert] = field(default_factory=dict)  # id -> latest state

    def update(self, facts: Facts) -> list[Alert]:
        """Compare the conditions now with the alerts up; the changes (also told to the
        listeners and logged)."""
        now_ids: dict[str, Condition] = {c.id: c for c in conditions(facts, self.cfg)}
        changes: list[Alert] = []
        for cid, condition in now_ids.items():
            if cid not in self.active:
                alert = Alert(cid, condition.kind, condition.text, "raised", facts.now)
                self.active[cid] = alert
                changes.append(alert)
        for cid in [cid for cid in self.active if cid not in now_ids]:
            up = self.active.pop(cid)
            changes.append(Alert(cid, up.kind, up.text, "cleared", up.since))
        for alert in changes:
            self._tell(facts.now, alert)
        return changes

    def acknowledge(self, alert_id: str, now: float) -> Alert | None:
        """A person saw it: None when there is no such alert to acknowledge."""
        seen = self.unacknowledged.get(alert_id)
        if seen is None:
            return None
        ack = Alert(seen.id, seen.kind, seen.text, "acknowledged", seen.since)
        self._tell(now, ack)
        return ack

    def shown(self) -> list[Alert]:
        """What the console's banner shows: every alert not yet acknowledged."""
        return sorted(self.unacknowledged.values(), key=lambda a: a.since)

    def _tell(self, now: float, alert: Alert) -> None:
        if alert.state == "acknowledged":
            self.unacknowledged.pop(alert.id, None)
        else:
            self.unacknowledged[alert.id] = alert
        level = logging.WARNING if alert.state == "raised" else logging.INFO
        log.log(level, "alert %s %s: %s", alert.id, alert.state, alert.text)
        for listener in self.listeners:
            listener(now, alert)
