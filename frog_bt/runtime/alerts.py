"""The robot asks for help: alerts raised once, cleared when their condition ends,
acknowledged by a person.

:func:`conditions` looks at one moment of the executive (a :class:`Facts`, pure data on
the project clock) and says which conditions hold now, each with one plain sentence and
what to do. :class:`AlertBook` turns that into changes: an alert is raised the first
time its condition holds, cleared when it no longer does (a one-off, such as a stop given
up, holds until the tour ends), and acknowledged by ``ack_alert``; one nobody acknowledges
is told again (escalation). Every change goes to the book's listeners: the log and status
line, the recording, the console and the webhooks (:mod:`frog_bt.live.console.webhooks`).

Each alert carries its kind's severity (REP-107: WARN or ERROR) and answers (the
commands of CONTRACT §7 that apply, :data:`KINDS`), and a stable deduplication key
(:func:`dedup_key`) that alert routers group and deduplicate by.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from msgspec.structs import replace

from frog_bt.config import AlertsCfg
from frog_bt.i18n import Msg, translator
from frog_bt.model.channels import Alert
from frog_bt.model.help import Help, HelpAbout

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
    help: Help | None = None  # the robot holds and asks a person (AskForHelp)
    stops_given_up: tuple[str, ...] = ()  # stops skipped this tour (navigation kept failing)
    pause_ran_out: bool = False  # this tour: a pause ended it
    # failures of the executive's own code that keep coming: (where, how many, the error)
    internal_errors: tuple[tuple[str, int, str], ...] = ()


Severity = Literal["WARN", "ERROR"]


@dataclass(frozen=True, slots=True)
class Kind:
    """What every alert of one kind shares: how bad it is (REP-107's levels) and the
    answers a person can give (commands of CONTRACT §7)."""

    severity: Severity
    answers: tuple[str, ...]


_HELP = ("retry", "done_by_hand", "service_off", "ack_alert")
KINDS: dict[str, Kind] = {
    "docking_failed": Kind("ERROR", _HELP),
    "undocking_failed": Kind("ERROR", _HELP),
    "gave_up": Kind("ERROR", _HELP),
    "fault_persists": Kind("ERROR", _HELP),
    "executive_crashed": Kind("ERROR", _HELP),
    "internal_error": Kind("ERROR", ("ack_alert",)),
    "fault": Kind("ERROR", ("service_off", "ack_alert")),
    "rosbridge_down": Kind("ERROR", ("ack_alert",)),
    "battery_low": Kind("WARN", ("home", "service_off", "ack_alert")),
    "frontend_silent": Kind("WARN", ("ack_alert",)),
    "no_visitor": Kind("WARN", ("service_off", "ack_alert")),
    "stop_given_up": Kind("WARN", ("ack_alert",)),
    "pause_ran_out": Kind("WARN", ("ack_alert",)),
}
OTHER = Kind("WARN", ("ack_alert",))  # a kind not in the table


NO_TODO = Msg("")


@dataclass(frozen=True, slots=True)
class Condition:
    kind: str  # docking_failed, stop_given_up, fault, battery_low, rosbridge_down, ...
    subject: str  # what it is about (the stop), "" when the kind says it all
    what: Msg  # one plain sentence: what is wrong
    todo: Msg = NO_TODO  # what to do

    @property
    def id(self) -> str:
        return f"{self.kind}:{self.subject}" if self.subject else self.kind

    @property
    def text(self) -> str:
        return self.say()

    def say(self, language: str = "en") -> str:
        """What is wrong and what to do, in ``language``."""
        words = translator(language)
        what, todo = self.what.say(words), self.todo.say(words)
        return f"{what} {todo}" if todo else what


def dedup_key(robot: str, kind: str, subject: str = "") -> str:
    """The stable deduplication key of an alert: the same for every change of it."""
    return f"frog-bt:{robot}:{kind}" + (f":{subject}" if subject else "")


_HELP_CONDITIONS = {
    HelpAbout.DOCK: Condition(
        "docking_failed",
        "",
        Msg("The robot could not dock after all its attempts."),
        Msg("Put it on its charger by hand and press Done, or clear the way and press Try again."),
    ),
    HelpAbout.UNDOCK: Condition(
        "undocking_failed",
        "",
        Msg("The robot could not leave its charger after all its attempts."),
        Msg("Move it off the charger by hand and press Done, or press Try again."),
    ),
    HelpAbout.HOME: Condition(
        "gave_up",
        "home",
        Msg("The robot could not get back to its charger."),
        Msg("Bring it to its charger and press Done, or clear the way and press Try again."),
    ),
    HelpAbout.FAULT: Condition(
        "fault_persists",
        "",
        Msg("The robot reports an electronics fault that does not go away; it starts no tour."),
        Msg("Call the robot team; press Done once the fault is fixed."),
    ),
}


def conditions(f: Facts, cfg: AlertsCfg, names: Callable[[str], str] = str) -> list[Condition]:
    """The conditions that hold now, in the order a person should read them (``names``:
    a stop's name as staff know it)."""
    out: list[Condition] = []
    if f.help is not None and f.help.about is HelpAbout.CRASHED:
        out.append(
            Condition(
                "executive_crashed",
                "",
                Msg(
                    "The executive stopped during a tour ({why}); it did not resume the tour, "
                    "so as not to stop again.",
                    why=f.help.detail or "?",
                ),
                Msg(
                    "Bring the robot to its charger and press Done, or press Try again to "
                    "send it home; tell the robot team."
                ),
            )
        )
    elif f.help is not None:  # the robot holds and waits for a person's answer
        out.append(_HELP_CONDITIONS[f.help.about])
    elif f.gave_up:  # a tree of its own gave up (GiveUp): the executive stops
        out.append(
            Condition(
                "gave_up",
                "",
                Msg("The robot stopped the tour: {why}.", why=f.gave_up),
                Msg("Check it, then restart it."),
            )
        )
    for stop in f.stops_given_up:
        out.append(
            Condition(
                "stop_given_up",
                stop,
                Msg("The robot could not reach {stop} and skipped it.", stop=names(stop)),
                Msg("Check that the way there is clear."),
            )
        )
    if f.faults:
        out.append(
            Condition(
                "fault",
                "",
                Msg(
                    "The robot reports an electronics fault: {faults}.", faults="; ".join(f.faults)
                ),
                Msg("Call the robot team."),
            )
        )
    if f.battery is not None and f.battery < cfg.battery_below:
        out.append(
            Condition(
                "battery_low",
                "",
                Msg("The battery is at {percent}%.", percent=f"{f.battery:.0f}"),
                Msg("Make sure the robot can reach its charger."),
            )
        )
    if (
        f.rosbridge_down_since is not None
        and f.now - f.rosbridge_down_since >= cfg.rosbridge_down_after
    ):
        out.append(
            Condition(
                "rosbridge_down",
                "",
                Msg(
                    "The executive cannot reach the robot (rosbridge) for {seconds} s.",
                    seconds=f"{f.now - f.rosbridge_down_since:.0f}",
                ),
                Msg("Check that the robot is on and on the network."),
            )
        )
    if (
        f.frontend_silent_since is not None
        and f.now - f.frontend_silent_since >= cfg.frontend_silent_after
    ):
        out.append(
            Condition(
                "frontend_silent",
                "",
                Msg(
                    "The screen and sound (front end) do not answer for {seconds} s.",
                    seconds=f"{f.now - f.frontend_silent_since:.0f}",
                ),
                Msg("Restart the front end."),
            )
        )
    if f.seeking_since is not None and f.now - f.seeking_since >= cfg.no_visitor_after:
        out.append(
            Condition(
                "no_visitor",
                "",
                Msg(
                    "No visitor has been found for {minutes} min.",
                    minutes=f"{(f.now - f.seeking_since) / 60:.0f}",
                ),
                Msg("Check that the robot stands where visitors pass and that its camera sees."),
            )
        )
    for where, count, error in f.internal_errors:
        out.append(
            Condition(
                "internal_error",
                where,
                Msg(
                    "The executive's own code failed {count} times at {where}: {error}.",
                    count=str(count),
                    where=where,
                    error=error,
                ),
                Msg("The tour goes on where it can; tell the robot team."),
            )
        )
    if f.pause_ran_out:
        out.append(
            Condition(
                "pause_ran_out",
                "",
                Msg("The tour was paused too long and ended."),
                Msg("The robot is going back to its dock."),
            )
        )
    return out


Listener = Callable[[float, Alert], None]


@dataclass
class AlertBook:
    """The alerts now: raised once per condition, cleared when it ends, acknowledged by a
    person. An alert stays shown (raised or cleared) until acknowledged.

    Escalation, on the project clock: a raised alert nobody has acknowledged is told
    again (the same alert, ``repeat`` counting up, ``waited`` its age) every
    ``cfg.escalate_every`` seconds, at most ``cfg.escalate_max`` times. It happens inside
    :meth:`update`, which the executive calls after every tick and between ticks, so a
    test drives it by moving ``Facts.now``."""

    cfg: AlertsCfg
    language: str = "en"  # the site's: alert texts and webhooks speak it
    names: Callable[[str], str] = str  # a stop's name as staff know it (POI2: its site name)
    listeners: list[Listener] = field(default_factory=list)
    active: dict[str, Alert] = field(default_factory=dict)  # id -> raised, not cleared
    unacknowledged: dict[str, Alert] = field(default_factory=dict)  # id -> latest state
    told_at: dict[str, float] = field(default_factory=dict)  # id -> last told (raised)
    logged: bool = True  # each change in the log (a replay's book is quiet)

    def update(self, facts: Facts) -> list[Alert]:
        """Compare the conditions now with the alerts up, and escalate what waits too
        long; the changes (also told to the listeners and logged)."""
        now_ids: dict[str, Condition] = {c.id: c for c in conditions(facts, self.cfg, self.names)}
        changes: list[Alert] = []
        for cid, condition in now_ids.items():
            if cid not in self.active:
                alert = self._alert(condition, facts.now)
                self.active[cid] = alert
                self.told_at[cid] = facts.now
                changes.append(alert)
        for cid in [cid for cid in self.active if cid not in now_ids]:
            up = self.active.pop(cid)
            self.told_at.pop(cid, None)
            changes.append(replace(up, state="cleared", repeat=0, waited=0.0))
        changes.extend(self._escalations(facts.now))
        for alert in changes:
            self._tell(facts.now, alert)
        return changes

    def _alert(self, condition: Condition, now: float) -> Alert:
        kind = KINDS.get(condition.kind, OTHER)
        return Alert(
            condition.id,
            condition.kind,
            condition.say(self.language),
            "raised",
            now,
            severity=kind.severity,
            key=dedup_key(self.cfg.robot, condition.kind, condition.subject),
            subject=condition.subject,
            answers=kind.answers,
            what=condition.what.say(translator(self.language)),
            todo=condition.todo.say(translator(self.language)),
        )

    def _escalations(self, now: float) -> list[Alert]:
        out: list[Alert] = []
        for cid, alert in self.active.items():
            shown = self.unacknowledged.get(cid)
            told = self.told_at.get(cid)
            if shown is None or told is None or shown.state != "raised":
                continue  # acknowledged: a person has it
            if shown.repeat >= self.cfg.escalate_max or now - told < self.cfg.escalate_every:
                continue
            self.told_at[cid] = now
            out.append(replace(alert, repeat=shown.repeat + 1, waited=now - alert.since))
        return out

    def acknowledge(self, alert_id: str, now: float) -> Alert | None:
        """A person saw it: None when there is no such alert to acknowledge."""
        seen = self.unacknowledged.get(alert_id)
        if seen is None:
            return None
        ack = replace(seen, state="acknowledged", repeat=0, waited=0.0)
        self._tell(now, ack)
        return ack

    def carried(self) -> tuple[list[Alert], list[Alert], dict[str, float]]:
        """The book now (active, not yet acknowledged, when each was last told), to be
        taken up by another book (a replay of a rotated file: :meth:`take_up`)."""
        return list(self.active.values()), list(self.unacknowledged.values()), dict(self.told_at)

    def take_up(self, active: list[Alert], shown: list[Alert], told_at: dict[str, float]) -> None:
        """Hold what another book held (:meth:`carried`); nothing is told."""
        self.active = {a.id: a for a in active}
        self.unacknowledged = {a.id: a for a in shown}
        self.told_at = dict(told_at)

    def shown(self) -> list[Alert]:
        """What the console's banner shows: every alert not yet acknowledged."""
        return sorted(self.unacknowledged.values(), key=lambda a: a.since)

    def _tell(self, now: float, alert: Alert) -> None:
        if alert.state == "acknowledged":
            self.unacknowledged.pop(alert.id, None)
        else:
            self.unacknowledged[alert.id] = alert
        if self.logged:
            self._log(alert)
        for listener in self.listeners:
            listener(now, alert)

    def _log(self, alert: Alert) -> None:
        level = logging.WARNING if alert.state == "raised" else logging.INFO
        if alert.repeat:
            log.log(
                level,
                "alert %s still %s after %.0f s (told again, %d of %d): %s",
                alert.id,
                alert.state,
                alert.waited,
                alert.repeat,
                self.cfg.escalate_max,
                alert.text,
            )
        else:
            log.log(level, "alert %s %s: %s", alert.id, alert.state, alert.text)
