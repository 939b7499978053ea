"""Each destination format against its published shape, with a local receiver on
127.0.0.1: the generic JSON, ntfy's JSON publish and Alertmanager's ``POST
/api/v2/alerts``. Alerts come from an :class:`AlertBook` fed :class:`Facts` with a moving
project-clock ``now``: raised, told again by escalation, then resolved."""

from __future__ import annotations

import asyncio
from typing import Any
from urllib.parse import unquote, urlsplit

import jsonschema
import pytest
from receivers import Got, Receiver

from frog_bt.config import AlertsCfg
from frog_bt.live.console.acklink import Verdict, link_key, verify
from frog_bt.live.console.alertbodies import HOLD, rfc3339, waited
from frog_bt.live.console.webhooks import Webhooks
from frog_bt.model import channels
from frog_bt.model.events import AlertChanged
from frog_bt.model.help import Help, HelpAbout
from frog_bt.runtime.alerts import AlertBook, Facts, dedup_key

TOKEN = "staff-token-0123"
CONSOLE = "https://frog.museum.example:8443"
WALL = 1_780_000_000.0  # the receivers' (wall) clock, fixed: times are exact

# ntfy's JSON publish (docs.ntfy.sh/publish/#publish-as-json): topic required
NTFY = {
    "type": "object",
    "required": ["topic"],
    "additionalProperties": False,
    "properties": {
        "topic": {"type": "string", "minLength": 1},
        "message": {"type": "string"},
        "title": {"type": "string"},
        "tags": {"type": "array", "items": {"type": "string"}},
        "priority": {"type": "integer", "minimum": 1, "maximum": 5},
        "click": {"type": "string", "format": "uri"},
        "actions": {
            "type": "array",
            "maxItems": 3,
            "items": {
                "type": "object",
                "required": ["action", "label", "url"],
                "properties": {
                    "action": {"enum": ["view", "http", "broadcast"]},
                    "label": {"type": "string"},
                    "url": {"type": "string"},
                    "clear": {"type": "boolean"},
                },
            },
        },
        "attach": {"type": "string"},
        "markdown": {"type": "boolean"},
        "icon": {"type": "string"},
        "filename": {"type": "string"},
        "delay": {"type": "string"},
        "email": {"type": "string"},
        "call": {"type": "string"},
    },
}
# Alertmanager's api/v2/openapi.yaml: postableAlerts = [postableAlert]
LABEL_SET = {"type": "object", "additionalProperties": {"type": "string"}}
ALERTMANAGER = {
    "type": "array",
    "items": {
        "type": "object",
        "required": ["labels"],
        "additionalProperties": False,
        "properties": {
            "labels": LABEL_SET,
            "annotations": LABEL_SET,
            "startsAt": {"type": "string", "format": "date-time"},
            "endsAt": {"type": "string", "format": "date-time"},
            "generatorURL": {"type": "string", "format": "uri"},
        },
    },
}
CHECKER = jsonschema.FormatChecker()


def cfg(*hooks: object, **more: Any) -> AlertsCfg:
    return AlertsCfg.model_validate(
        {
            "webhooks": list(hooks),
            "console_url": CONSOLE,
            "escalate_every": 600,
            "escalate_max": 2,
            "webhook_backoff": 0.01,
            **more,
        }
    )


async def drive(cfg: AlertsCfg, receiver: Receiver, n: int, **facts: Any) -> list[Got]:
    """Raise (at t=1000), two escalations (t=1600, 2200; none at 1599 nor, past the
    bound, at 2800), then the condition ends (t=2900): what ``receiver`` got."""
    book = AlertBook(cfg)
    hooks = Webhooks(cfg, ack_secret=TOKEN, wall=lambda: WALL)
    book.listeners.append(hooks.notify)
    hooks.start()
    try:
        for now in (1000.0, 1599.0, 1600.0, 2200.0, 2800.0):
            book.update(Facts(now=now, **facts))
        book.update(Facts(now=2900.0))
        return await receiver.wait_for(n)
    finally:
        await hooks.finish()


def check_link(url: str, alert_id: str) -> None:
    parts = urlsplit(url)
    assert f"{parts.scheme}://{parts.netloc}" == CONSOLE
    assert unquote(parts.path) == f"/ack/{alert_id}" and TOKEN not in url
    query = dict(p.split("=") for p in parts.query.split("&"))
    assert int(query["exp"]) == WALL + 86400  # alerts.ack_link_ttl, on the wall clock
    at = unquote(query["at"])  # the raise it acknowledges: the alert's raise time
    key = link_key(TOKEN)
    assert verify(key, "frog", alert_id, at, query["exp"], query["sig"], WALL) is Verdict.VALID


def test_generic_json_raised_escalated_twice_then_resolved() -> None:
    async def main() -> list[Got]:
        async with Receiver() as r:
            return await drive(cfg(f"{r.url}/hook"), r, 4, battery=20.0)

    got = asyncio.run(main())
    assert [g.path for g in got] == ["/hook"] * 4
    bodies = [g.body for g in got]
    assert [(b["state"], b["repeat"], b.get("waited")) for b in bodies] == [
        ("raised", 0, None),
        ("raised", 1, 600.0),
        ("raised", 2, 1200.0),
        ("cleared", 0, None),
    ]
    first = bodies[0]
    assert {
        k: first[k]
        for k in ("id", "kind", "severity", "key", "answers", "robot", "since", "console")
    } == {
        "id": "battery_low",
        "kind": "battery_low",
        "severity": "WARN",
        "key": "frog-bt:frog:battery_low",
        "answers": ["home", "service_off", "ack_alert"],
        "robot": "frog",
        "since": 1000.0,
        "console": CONSOLE,
    }
    assert first["text"] == ("The battery is at 20%. Make sure the robot can reach its charger.")
    assert first["what"] == "The battery is at 20%."
    assert first["todo"] == "Make sure the robot can reach its charger."
    assert all(b["key"] == first["key"] for b in bodies)  # one key for every change
    check_link(first["ack_url"], "battery_low")
    assert got[0].headers["Content-Type"] == "application/json"


def test_ntfy_json_publish_at_the_root_priority_from_severity() -> None:
    async def main() -> list[Got]:
        async with Receiver() as r:
            hook = {"url": f"{r.url}/frog-alerts", "format": "ntfy"}
            return await drive(cfg(hook), r, 4, faults=("motors: overheated",))

    got = asyncio.run(main())
    assert [g.path for g in got] == ["/"] * 4  # published as JSON at the server's root
    for g in got:
        jsonschema.validate(g.body, NTFY, format_checker=CHECKER)
        assert g.body["topic"] == "frog-alerts" and g.body["click"] == CONSOLE
    raised, again, _, resolved = (g.body for g in got)
    assert raised["title"] == "frog needs help: electronics fault"
    assert raised["priority"] == 5
    assert raised["tags"] == ["rotating_light", "electronics fault", "frog", "error"]
    assert raised["message"] == (
        "The robot reports an electronics fault: motors: overheated. Call the robot team.\n"
        "Answers: Out of service, Seen."
    )
    assert again["title"] == "frog still needs help after 10 min: electronics fault"
    assert again["message"].startswith("Nobody has acknowledged this for 10 min.\n")
    assert again["priority"] == 5
    [action] = raised["actions"]
    assert action["action"] == "view" and action["label"] == "Acknowledge"
    check_link(action["url"], "fault")
    assert resolved["priority"] == 3
    assert resolved["title"] == "frog: resolved: electronics fault"
    assert resolved["tags"][0] == "white_check_mark"


def test_ntfy_priority_4_for_a_warning() -> None:
    async def main() -> list[Got]:
        async with Receiver() as r:
            hook = {"url": f"{r.url}/base/t0p1c", "format": "ntfy"}
            return await drive(cfg(hook, escalate_max=0), r, 2, battery=10.0)

    got = asyncio.run(main())
    assert [(g.path, g.body["topic"], g.body["priority"]) for g in got] == [
        ("/base/", "t0p1c", 4),
        ("/base/", "t0p1c", 3),
    ]


def test_alertmanager_post_api_v2_alerts_labels_annotations_and_times() -> None:
    async def main() -> list[Got]:
        async with Receiver() as r:
            hook = {"url": r.url, "format": "alertmanager"}
            return await drive(cfg(hook), r, 4, stops_given_up=("POI3",))

    got = asyncio.run(main())
    assert [g.path for g in got] == ["/api/v2/alerts"] * 4
    for g in got:
        jsonschema.validate(g.body, ALERTMANAGER, format_checker=CHECKER)
    alerts = [g.body[0] for g in got]
    assert all(
        a["labels"]
        == {
            "alertname": "FrogRobotNeedsHelp",
            "robot": "frog",
            "kind": "stop_given_up",
            "subject": "POI3",
            "severity": "WARN",
        }
        for a in alerts
    )  # one identity
    raised, again, _, resolved = alerts
    assert raised["annotations"]["summary"] == "The robot could not reach POI3 and skipped it."
    assert raised["annotations"]["description"] == "Check that the way there is clear."
    assert raised["annotations"]["dedup_key"] == dedup_key("frog", "stop_given_up", "POI3")
    assert raised["generatorURL"] == CONSOLE
    assert raised["startsAt"] == rfc3339(WALL) == "2026-05-28T20:26:40.000Z"
    assert raised["endsAt"] == rfc3339(WALL + HOLD)  # firing: kept alive by re-sending
    assert again["annotations"]["waited"] == "10 min without acknowledgement"
    assert resolved["startsAt"] == raised["startsAt"] and resolved["endsAt"] == rfc3339(WALL)
    check_link(raised["annotations"]["ack_url"], "stop_given_up:POI3")


def test_no_links_without_a_console_url_or_a_token() -> None:
    async def main() -> list[list[Got]]:
        out = []
        for console_url, secret in (("", TOKEN), (CONSOLE, None)):
            async with Receiver() as r:
                c = cfg(f"{r.url}/hook", console_url=console_url)
                book, hooks = AlertBook(c), Webhooks(c, ack_secret=secret)
                book.listeners.append(hooks.notify)
                hooks.start()
                book.update(Facts(now=1.0, battery=5.0))
                out.append(await r.wait_for(1))
                await hooks.finish()
        return out

    no_console, no_token = asyncio.run(main())
    assert "ack_url" not in no_console[0].body and "console" not in no_console[0].body
    assert "ack_url" not in no_token[0].body and no_token[0].body["console"] == CONSOLE


def test_severities_answers_and_keys_per_kind() -> None:
    book = AlertBook(AlertsCfg(robot="frog-2"))
    changes = book.update(
        Facts(
            now=1000.0,
            battery=5.0,
            faults=("x",),
            help=Help(HelpAbout.DOCK, 900.0),
            gave_up="docking failed",
            stops_given_up=("POI1",),
            rosbridge_down_since=0.0,
            frontend_silent_since=0.0,
            seeking_since=0.0,
            pause_ran_out=True,
        )
    )
    got = {a.id: (a.severity, a.key, a.answers[-1]) for a in changes}
    assert {k: s for k, (s, _, _) in got.items()} == {
        "docking_failed": "ERROR",
        "stop_given_up:POI1": "WARN",
        "fault": "ERROR",
        "battery_low": "WARN",
        "rosbridge_down": "ERROR",
        "frontend_silent": "WARN",
        "no_visitor": "WARN",
        "pause_ran_out": "WARN",
    }
    assert got["stop_given_up:POI1"][1] == "frog-bt:frog-2:stop_given_up:POI1"
    assert all(last == "ack_alert" for _, _, last in got.values())
    docking = next(a for a in changes if a.kind == "docking_failed")
    assert docking.answers == ("retry", "done_by_hand", "service_off", "ack_alert")


def test_escalation_stops_once_acknowledged_and_is_bounded() -> None:
    book = AlertBook(AlertsCfg(escalate_every=60, escalate_max=3))
    told: list[tuple[float, int]] = []
    book.listeners.append(lambda t, a: told.append((t, a.repeat)))
    for now in range(0, 1000, 10):
        book.update(Facts(now=float(now), battery=5.0))
    assert told == [(0.0, 0), (60.0, 1), (120.0, 2), (180.0, 3)]  # then no more
    book2 = AlertBook(AlertsCfg(escalate_every=60))
    book2.update(Facts(now=0.0, battery=5.0))
    assert book2.acknowledge("battery_low", 30.0) is not None
    assert book2.update(Facts(now=600.0, battery=5.0)) == []  # a person has it


@pytest.mark.parametrize("seconds, words", [(45, "45 s"), (600, "10 min"), (7500, "2 h 5 min")])
def test_waited_in_plain_words(seconds: float, words: str) -> None:
    assert waited(seconds) == words


def test_an_alert_recorded_before_these_fields_still_decodes() -> None:
    old = b'{"type":"AlertChanged","t":1.0,"alert":{"id":"fault","kind":"fault","text":"x",'
    old += b'"state":"raised","since":1.0}}'
    changed = channels.decode(channels.ALERT, old)
    assert isinstance(changed, AlertChanged)
    alert = changed.alert
    assert (alert.severity, alert.key, alert.answers, alert.repeat) == ("WARN", "", (), 0)
    new = AlertChanged(1.0, AlertBook(AlertsCfg()).update(Facts(now=1.0, faults=("x",)))[0])
    assert channels.decode(channels.ALERT, channels.encode(new)) == new
