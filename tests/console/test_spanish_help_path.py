"""No English word reaches staff on the help path, for any destination, at a site that
speaks Spanish (``language: es``, the Alcázar's): a dock that fails after its attempts is
raised, told again, acknowledged and resolved, and each destination's words a person
reads are checked — the generic JSON's ``text``, ``what`` and ``todo``; ntfy's title,
message, tags and action label; Alertmanager's annotations; and, on a running console,
the refusal of *Hecho* before the robot is docked, the help panel's words, the day's list,
the acknowledgement link's page and ``frog-bt ctl status``.
"""

from __future__ import annotations

import asyncio
import re
from typing import Any

import aiohttp
import pytest
from console_tour import auth, console_tour
from receivers import Got, Receiver
from test_faults import is_
from tour import after_ticks

from frog_bt.commands.ctl import state_lines
from frog_bt.config import AlertsCfg
from frog_bt.live.console.webhooks import Webhooks
from frog_bt.model import keys
from frog_bt.model.help import Help, HelpAbout
from frog_bt.runtime.alerts import AlertBook, Facts

TOKEN = "staff-token-0123"
# English words our sentences are made of that Spanish does not share (a slip into
# English shows as one of them); the robot's name ("frog") and codes in URLs are not read
ENGLISH = set(
    [
        "the",
        "needs",
        "need",
        "help",
        "resolved",
        "acknowledged",
        "acknowledge",
        "answers",
        "answer",
        "retry",
        "done",
        "hand",
        "service",
        "off",
        "ack",
        "alert",
        "alerts",
        "tour",
        "aborted",
        "ended",
        "stop",
        "stops",
        "operator",
        "docked",
        "undocked",
        "failed",
        "docking",
        "undocking",
        "someone",
        "nobody",
        "still",
        "after",
        "without",
        "yes",
        "warning",
        "skipped",
        "try",
        "again",
        "seen",
        "send",
        "home",
        "not",
        "valid",
        "link",
        "nothing",
        "refused",
        "could",
        "dock",
        "charger",
        "its",
        "was",
        "what",
        "with",
        "fault",
        "electronics",
        "battery",
        "low",
        "stuck",
        "reports",
        "and",
        "this",
        "for",
        "has",
        "been",
        "by",
        "of",
        "on",
        "to",
        "it",
        "is",
        "person",
        "waiting",
        "answered",
        "minutes",
    ]
)


def english(text: str) -> list[str]:
    """The English words of ``text`` (a command to type, ``frog-bt ctl retry``, is a name)."""
    text = re.sub(r"frog-bt ctl [a-z_]+( [a-z_]+)?", " ", text.lower())
    return sorted({w for w in re.findall(r"[a-záéíóúñü]+", text) if w in ENGLISH})


def read_words(fmt: str, body: Any) -> list[str]:
    """What a person reads of one destination's body."""
    if fmt == "json":
        return [body["text"], body["what"], body["todo"]]
    if fmt == "ntfy":
        emoji = {"rotating_light", "warning", "white_check_mark", "ok_hand"}
        tags = [t for t in body["tags"] if t not in emoji and t != "frog"]
        return [
            body["title"],
            body["message"],
            *tags,
            *(a["label"] for a in body.get("actions", [])),
        ]
    [alert] = body
    shown = ("summary", "description", "text", "answers", "waited", "acknowledged")
    return [v for k, v in alert["annotations"].items() if k in shown]


@pytest.mark.parametrize("fmt", ["json", "ntfy", "alertmanager"])
def test_every_destination_speaks_spanish_on_the_help_path(fmt: str) -> None:
    async def main() -> list[Got]:
        async with Receiver() as r:
            hook = {"url": f"{r.url}/frog-help", "format": fmt}
            cfg = AlertsCfg.model_validate(
                {
                    "webhooks": [hook],
                    "console_url": "https://frog.museum.example",
                    "escalate_every": 600,
                    "escalate_max": 1,
                    "webhook_backoff": 0.01,
                }
            )
            book = AlertBook(cfg, language="es")
            hooks = Webhooks(cfg, ack_secret=TOKEN, language="es")
            book.listeners.append(hooks.notify)
            hooks.start()
            help_ = Help(HelpAbout.DOCK, 1000.0)
            try:
                book.update(Facts(now=1000.0, help=help_))  # raised
                book.update(Facts(now=1600.0, help=help_))  # told again
                book.acknowledge("docking_failed", 1700.0)  # someone has it
                book.update(Facts(now=1800.0))  # resolved
                return await r.wait_for(4 if fmt != "alertmanager" else 3)
            finally:
                await hooks.finish()

    got = asyncio.run(main())
    assert got
    for g in got:
        for text in read_words(fmt, g.body):
            assert not english(text), (fmt, text, english(text))


def test_the_console_and_ctl_speak_spanish_on_the_help_path() -> None:
    async def main() -> tuple[list[str], dict[str, Any]]:
        scenario = {"docking": {"dock_failures": 3}}
        async with console_tour(scenario, once=False) as (run, _people, url):
            exe = run.executive
            await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is not None, 60)
            said: list[str] = []
            async with aiohttp.ClientSession() as session:
                # no ?lang=: the site's language, as frog-bt ctl and scripts get it
                async with session.post(
                    f"{url}/api/command", json={"command": "done_by_hand"}, headers=auth()
                ) as r:
                    assert r.status == 409
                    said.append((await r.json())["reason"])
                async with session.get(f"{url}/ack/docking_failed?at=1&exp=1&sig=x") as r:
                    assert r.status == 403
                    said.append(re.sub(r"<[^>]+>", " ", await r.text()))
                async with session.get(f"{url}/api/state") as r:
                    state = await r.json()
                said += [state["help"]["what"], state["help"]["by_hand"], state["doing"]]
                said += [a["text"] for a in state["alerts"]]
                said += state_lines(state)[1:]  # the first line: the phase, as the tree says
                docking = run.sim.world.docking  # a person puts the robot on its charger
                docking.state, docking.docked = "docked", True
                await after_ticks(exe, lambda: _docked(exe), 30)
                async with session.post(
                    f"{url}/api/command", json={"command": "done_by_hand"}, headers=auth()
                ) as r:
                    assert r.status == 200
                    said.append((await r.json())["did"])
                await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None, 30)
                await run.sim.wait_for(is_("tour", state="ended"), 60)
                async with session.get(f"{url}/api/state") as r:
                    state = await r.json()
            return said, state

    said, state = asyncio.run(main())
    assert state["day"]["last"], state["day"]
    said += state["day"]["last"]
    for text in said:
        assert not english(text), (text, english(text))


def _docked(exe: Any) -> bool:
    reading = exe.core.board.get(keys.DOCKING)
    return reading is not None and reading.value == "docked"
