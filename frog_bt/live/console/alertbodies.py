"""What one alert change looks like to each kind of receiver: sans-I/O, bodies as values.

* :func:`generic` — our JSON: the alert's fields, ``robot``, and ``waited`` when told again
  (``repeat`` > 0), ``console`` and ``ack_url`` when there are links;
* :func:`ntfy` — ntfy's JSON publish (``POST`` to the server's root): ``topic``, ``title``,
  ``message``, ``priority`` (ERROR 5, WARN 4, resolved 3, acknowledged 2), ``tags``,
  ``click`` (the console) and a *view* action opening the acknowledgement link;
* :func:`alertmanager` — Alertmanager's ``POST /api/v2/alerts``: a list of alerts with
  ``labels`` (a stable ``alertname`` plus robot, kind, subject, severity: the alert's
  identity), ``annotations`` (``summary`` the sentence, ``description`` what to do),
  ``startsAt``, ``endsAt`` and ``generatorURL``.

Alertmanager forgets an alert whose ``endsAt`` has passed, and its clients are to re-send
firing alerts while they last: a firing alert's ``endsAt`` is ``HOLD`` seconds ahead, and
the sender (:mod:`.webhooks`) re-sends it every ``REFRESH`` seconds; a cleared alert is
sent with ``endsAt`` = the time it cleared (resolved). An acknowledged alert still fires
there while its condition holds (in Alertmanager, a silence is what quiets it), with
``acknowledged: yes``.

Times here are wall-clock epoch seconds, taken as the change was queued: receivers live
in real time, whatever clock the executive runs on.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit, urlunsplit

from frog_bt.config import Webhook
from frog_bt.i18n import N_, Msg, translator
from frog_bt.model.channels import Alert

ALERTNAME = "FrogRobotNeedsHelp"
TEXT_MAX = 1000  # characters of one text field (a fault's text comes from the robot)
REFRESH = 60.0  # wall seconds between re-sends of firing alerts to Alertmanager
HOLD = 4 * REFRESH  # a firing alert's endsAt is this far ahead (as Prometheus does)
PRIORITY = {"ERROR": 5, "WARN": 4}  # ntfy: urgent, high
RESOLVED, ACKNOWLEDGED = 3, 2  # ntfy: default, low


@dataclass(frozen=True, slots=True)
class Outgoing:
    """One alert change to tell: the alert, the wall time of the change, the wall time it
    was raised, and the link acknowledging it ("" when there is none)."""

    alert: Alert
    at: float
    started: float
    ack_url: str = ""


@dataclass(frozen=True, slots=True)
class Sender:
    """Who tells: the robot's name, the console's public URL ("" when none) and the
    site's language (every word a person reads on a phone is in it)."""

    robot: str
    console_url: str = ""
    language: str = "en"

    def say(self, msg: Msg) -> str:
        return msg.say(translator(self.language))


# What staff call each kind of alert and each answer (the page's buttons' words).
KIND_WORDS = {
    "docking_failed": N_("docking failed"),
    "undocking_failed": N_("undocking failed"),
    "gave_up": N_("could not go on"),
    "fault_persists": N_("fault persists"),
    "executive_crashed": N_("executive stopped during a tour"),
    "internal_error": N_("internal error"),
    "fault": N_("electronics fault"),
    "rosbridge_down": N_("robot unreachable"),
    "battery_low": N_("battery low"),
    "frontend_silent": N_("screen and sound silent"),
    "no_visitor": N_("no visitor"),
    "stop_given_up": N_("stop given up"),
    "pause_ran_out": N_("pause ran out"),
}
ANSWER_WORDS = {
    "retry": N_("Try again"),
    "done_by_hand": N_("Done"),
    "service_off": N_("Out of service"),
    "service_on": N_("Back in service"),
    "home": N_("Send home"),
    "ack_alert": N_("Seen"),
}
SEVERITY_WORDS = {"ERROR": N_("error"), "WARN": N_("warning")}


def kind_words(kind: str, sender: Sender) -> str:
    """An alert's kind as staff call it, in the site's language."""
    words = KIND_WORDS.get(kind)
    return sender.say(Msg(words)) if words else kind.replace("_", " ")


def answer_words(answers: tuple[str, ...] | list[str], sender: Sender) -> str:
    """The commands that answer an alert, by the page's buttons' words."""
    return ", ".join(sender.say(Msg(ANSWER_WORDS[a])) if a in ANSWER_WORDS else a for a in answers)


def target(hook: Webhook) -> str:
    """The URL a destination's POSTs go to."""
    parts = urlsplit(hook.url)
    if hook.format == "ntfy":  # the topic is the last segment; publish at the root above
        base = parts.path.rstrip("/").rpartition("/")[0]
        return urlunsplit((parts.scheme, parts.netloc, base + "/", "", ""))
    if hook.format == "alertmanager":
        path = parts.path.rstrip("/")
        if not path.endswith("/api/v2/alerts"):
            path += "/api/v2/alerts"
        return urlunsplit((parts.scheme, parts.netloc, path, parts.query, ""))
    return hook.url


def ntfy_topic(hook: Webhook) -> str:
    return urlsplit(hook.url).path.rstrip("/").rpartition("/")[2]


def body(hook: Webhook, out: Outgoing, sender: Sender) -> Any:
    """The JSON value telling ``out`` to ``hook``."""
    if hook.format == "ntfy":
        return ntfy(out, sender, ntfy_topic(hook))
    if hook.format == "alertmanager":
        return alertmanager([out], sender)
    return generic(out, sender)


# ---------------------------------------------------------------- the shapes


def generic(out: Outgoing, sender: Sender) -> dict[str, Any]:
    a = out.alert
    payload: dict[str, Any] = {
        "id": a.id,
        "kind": a.kind,
        "text": _short(a.text),
        "state": a.state,
        "since": a.since,
        "robot": sender.robot,
        "severity": a.severity,
        "key": a.key,
        "subject": a.subject,
        "answers": list(a.answers),
        "what": _short(a.what),
        "todo": _short(a.todo),
        "repeat": a.repeat,
    }
    if a.repeat:
        payload["waited"] = a.waited
    if sender.console_url:
        payload["console"] = sender.console_url
    if out.ack_url:
        payload["ack_url"] = out.ack_url
    return payload


def ntfy(out: Outgoing, sender: Sender, topic: str) -> dict[str, Any]:
    a = out.alert
    say = sender.say
    label = kind_words(a.kind, sender) + (f" ({a.subject})" if a.subject else "")
    text = _short(a.what or a.text)
    robot = sender.robot
    if a.state == "cleared":
        title = say(Msg("{robot}: resolved: {what}", robot=robot, what=label))
        priority, icon = RESOLVED, "white_check_mark"
        lines = [say(Msg("Resolved: {text}", text=text))]
    elif a.state == "acknowledged":
        title = say(Msg("{robot}: acknowledged: {what}", robot=robot, what=label))
        priority, icon = ACKNOWLEDGED, "ok_hand"
        lines = [say(Msg("Someone has it: {text}", text=text))]
    else:
        priority = PRIORITY[a.severity]
        icon = "rotating_light" if a.severity == "ERROR" else "warning"
        title = say(
            Msg(
                "{robot} still needs help after {time}: {what}",
                robot=robot,
                time=waited(a.waited),
                what=label,
            )
            if a.repeat
            else Msg("{robot} needs help: {what}", robot=robot, what=label)
        )
        lines = [_short(a.text)]
        if a.repeat:
            lines.insert(
                0, say(Msg("Nobody has acknowledged this for {time}.", time=waited(a.waited)))
            )
        if a.answers:
            lines.append(say(Msg("Answers: {answers}.", answers=answer_words(a.answers, sender))))
    payload: dict[str, Any] = {
        "topic": topic,
        "title": title,
        "message": "\n".join(lines),
        "priority": priority,
        "tags": [icon, kind_words(a.kind, sender), robot, say(Msg(SEVERITY_WORDS[a.severity]))],
    }
    if sender.console_url:
        payload["click"] = sender.console_url
    if out.ack_url and a.state != "acknowledged":
        payload["actions"] = [
            {
                "action": "view",
                "label": say(Msg("Acknowledge")),
                "url": out.ack_url,
                "clear": True,
            }
        ]
    return payload


def alertmanager(outs: list[Outgoing], sender: Sender) -> list[dict[str, Any]]:
    return [_am_alert(out, sender) for out in outs]


def _am_alert(out: Outgoing, sender: Sender) -> dict[str, Any]:
    a = out.alert
    labels = {"alertname": ALERTNAME, "robot": sender.robot, "kind": a.kind, "severity": a.severity}
    if a.subject:
        labels["subject"] = a.subject
    annotations = {
        "summary": _short(a.what or a.text),
        "description": _short(a.todo),
        "text": _short(a.text),
        "dedup_key": a.key,
        "answers": answer_words(a.answers, sender),
    }
    if a.repeat:
        annotations["waited"] = sender.say(
            Msg("{time} without acknowledgement", time=waited(a.waited))
        )
    if a.state == "acknowledged":
        annotations["acknowledged"] = sender.say(Msg("yes"))
    if out.ack_url:
        annotations["ack_url"] = out.ack_url
    ends = out.at if a.state == "cleared" else out.at + HOLD
    payload: dict[str, Any] = {
        "labels": labels,
        "annotations": annotations,
        "startsAt": rfc3339(out.started),
        "endsAt": rfc3339(ends),
    }
    if sender.console_url:
        payload["generatorURL"] = sender.console_url
    return payload


# ---------------------------------------------------------------- words and times


def rfc3339(epoch: float) -> str:
    stamp = dt.datetime.fromtimestamp(epoch, dt.UTC).isoformat(timespec="milliseconds")
    return stamp.replace("+00:00", "Z")


def waited(seconds: float) -> str:
    """``seconds`` in plain words: 45 s, 20 min, 2 h 5 min."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    minutes = round(seconds / 60)
    if minutes < 120:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60} min"


def _short(text: str) -> str:
    return text if len(text) <= TEXT_MAX else text[: TEXT_MAX - 1] + "…"
