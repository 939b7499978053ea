"""A shift handed over: what the next shift needs to know, as a value, in words and in
the bodies the webhooks send (sans-I/O).

A :class:`Handover` is composed by :class:`~frog_bt.live.console.shift.Shift` from what it
saw since the last one: the tours (started, completed, ended early), the help requests
(what, when, who answered and how fast), the alerts still open, the out-of-service
periods, and what the robot still waits for. :func:`sections` says it in the site's
language (the page's *Relevo*, ntfy's message, the generic JSON's ``text``); times are
local (the site's clock), on the project clock.

Who did something (the ``by`` of a command) is said by :func:`who`: ``console``,
``ctl``, ``link`` in words, a paired device by its name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, tzinfo
from typing import Any

from frog_bt.i18n import N_, Msg, say
from frog_bt.live.console.alertbodies import TEXT_MAX, Sender, waited
from frog_bt.text import inert

__all__ = ["Asked", "Handover", "OpenAlert", "Period", "generic", "ntfy", "sections", "who"]

NAME_MAX = 64  # characters of a device's name shown
SENDERS = {
    "console": N_("someone at the console"),
    "ctl": N_("the robot team (ctl)"),
    "link": N_("a notification's link"),
}
ANSWERS = {"retry": N_("Try again"), "done_by_hand": N_("Done")}


def who(by: str) -> Msg | str:
    """Who sent a command, in words: a paired device by its name (``device:NAME``, made
    inert and bounded), the console, ``ctl`` or a link in the site's words."""
    if by.startswith("device:"):
        return inert(by.removeprefix("device:"), NAME_MAX)
    words = SENDERS.get(by)
    return Msg(words) if words else Msg(N_("someone"))


@dataclass(slots=True)
class Asked:
    """One help request: what (``HelpAbout``'s words, a msgid), since when, and once it
    is over, when, by whom (``by`` of the command; "" when the robot saw the step done by
    itself) and with which answer (``retry``, ``done_by_hand``)."""

    about: str
    what: str
    since: float
    answered: float | None = None
    by: str = ""
    answer: str = ""


@dataclass(slots=True)
class Period:
    """Out of service from ``since`` until ``until`` (None: still), put so ``by``."""

    since: float
    until: float | None = None
    by: str = ""
    back_by: str = ""


@dataclass(frozen=True, slots=True)
class OpenAlert:
    id: str
    kind: str
    text: str
    since: float
    acknowledged: bool


@dataclass(frozen=True)
class Handover:
    """What one shift hands to the next: from ``since`` to ``at`` (project clock),
    composed on schedule (``asked_by`` "") or when someone asked (their ``by``)."""

    at: float
    since: float
    asked_by: str
    tours: dict[str, int]
    asked: tuple[Asked, ...]
    alerts: tuple[OpenAlert, ...]
    out_of_service: tuple[Period, ...]
    waiting: tuple[Msg, ...] = field(default=())


def _hm(t: float, tz: tzinfo) -> str:
    return datetime.fromtimestamp(t, tz).strftime("%H:%M")


def title(h: Handover, robot: str, tz: tzinfo) -> Msg:
    return Msg("{robot}: shift handover at {time}", robot=robot, time=_hm(h.at, tz))


def sections(h: Handover, tz: tzinfo) -> list[tuple[Msg, list[Msg | str]]]:
    """The handover as headed lists of sentences (not yet translated)."""
    t = h.tours
    tours: list[Msg | str] = [
        Msg(
            "{started} started, {completed} completed, {aborted} ended early",
            started=t["started"],
            completed=t["completed"],
            aborted=t["aborted"],
        )
    ]
    helped: list[Msg | str] = [_asked(a, h.at, tz) for a in h.asked] or [
        Msg("the robot asked for no help")
    ]
    alerts: list[Msg | str] = [
        Msg("{text} (since {time}; seen)", text=a.text[:TEXT_MAX], time=_hm(a.since, tz))
        if a.acknowledged
        else Msg("{text} (since {time}; not seen)", text=a.text[:TEXT_MAX], time=_hm(a.since, tz))
        for a in h.alerts
    ] or [Msg("no alert is open")]
    periods: list[Msg | str] = [_period(p, tz) for p in h.out_of_service] or [Msg("never")]
    return [
        (Msg("Tours since {time}", time=_hm(h.since, tz)), tours),
        (Msg("Help requests"), helped),
        (Msg("Alerts still open"), alerts),
        (Msg("Out of service"), periods),
        (Msg("The robot still waits for"), list(h.waiting) or [Msg("nothing")]),
    ]


def _asked(a: Asked, now: float, tz: tzinfo) -> Msg:
    what = Msg(a.what)
    if a.answered is None:
        return Msg(
            "{time}: {what} Still waiting, for {wait}.",
            time=_hm(a.since, tz),
            what=what,
            wait=waited(now - a.since),
        )
    if not a.by:
        return Msg(
            "{time}: {what} The robot went on by itself after {wait}.",
            time=_hm(a.since, tz),
            what=what,
            wait=waited(a.answered - a.since),
        )
    return Msg(
        "{time}: {what} Answered «{answer}» by {who} after {wait}.",
        time=_hm(a.since, tz),
        what=what,
        answer=Msg(ANSWERS.get(a.answer, a.answer)),
        who=who(a.by),
        wait=waited(a.answered - a.since),
    )


def _period(p: Period, tz: tzinfo) -> Msg:
    if p.until is None:
        return Msg("since {start}, still (by {who})", start=_hm(p.since, tz), who=who(p.by))
    return Msg(
        "{start}-{end} (by {who})", start=_hm(p.since, tz), end=_hm(p.until, tz), who=who(p.by)
    )


def text(h: Handover, lang: str, tz: tzinfo) -> str:
    """The whole handover as plain text in ``lang``: a heading per section, a line each."""
    lines = []
    for heading, items in sections(h, tz):
        lines.append(say(heading, lang) + ":")
        lines.extend("• " + say(item, lang) for item in items)
    return "\n".join(lines)


def shown(h: Handover, robot: str, lang: str, tz: tzinfo) -> dict[str, Any]:
    """The handover as the page shows it: its title and sections, in ``lang``."""
    return {
        "at": h.at,
        "since": h.since,
        "title": say(title(h, robot, tz), lang),
        "sections": [
            {"title": say(heading, lang), "lines": [say(item, lang) for item in items]}
            for heading, items in sections(h, tz)
        ],
    }


# ---------------------------------------------------------------- the webhooks' bodies


def generic(h: Handover, sender: Sender, tz: tzinfo) -> dict[str, Any]:
    """The generic JSON: ``type: handover``, the figures, and ``text`` in the site's
    language."""
    payload: dict[str, Any] = {
        "type": "handover",
        "robot": sender.robot,
        "at": h.at,
        "since": h.since,
        "title": sender.say(title(h, sender.robot, tz)),
        "tours": dict(h.tours),
        "help": [
            {
                "about": a.about,
                "since": a.since,
                "answered": a.answered,
                "by": a.by[: NAME_MAX + 7],
                "answer": a.answer,
            }
            for a in h.asked
        ],
        "alerts": [
            {"id": a.id, "kind": a.kind, "since": a.since, "acknowledged": a.acknowledged}
            for a in h.alerts
        ],
        "out_of_service": [
            {"since": p.since, "until": p.until, "by": p.by[: NAME_MAX + 7]}
            for p in h.out_of_service
        ],
        "text": text(h, sender.language, tz)[: TEXT_MAX * 4],
    }
    if sender.console_url:
        payload["console"] = sender.console_url
    return payload


def ntfy(h: Handover, sender: Sender, topic: str, tz: tzinfo) -> dict[str, Any]:
    """ntfy's JSON publish: the title, the text as the message, default priority."""
    payload: dict[str, Any] = {
        "topic": topic,
        "title": sender.say(title(h, sender.robot, tz)),
        "message": text(h, sender.language, tz)[: TEXT_MAX * 4],
        "priority": 3,
        "tags": ["clipboard", sender.robot],
    }
    if sender.console_url:
        payload["click"] = sender.console_url
    return payload
