"""A robot that needs a person, as staff meet it through the console (sim time): the
state's ``help``, the alert on a webhook and again by escalation, the answer from the
API, and the robot going on."""

from __future__ import annotations

import asyncio
from typing import Any

import aiohttp
from console_tour import command, console_tour
from receivers import Receiver

from frog_bt.config import load_site
from frog_bt.model.events import OperatorDone
from frog_bt.runtime.observer import listen


def test_a_failed_dock_is_shown_escalated_and_answered_from_the_api() -> None:
    async def main() -> dict[str, Any]:
        async with Receiver() as hook:
            site = load_site()
            alerts = site.alerts.model_copy(
                update={"webhooks": [hook.url], "escalate_every": 60.0, "escalate_max": 2}
            )
            site = site.model_copy(update={"alerts": alerts})
            scenario = {"docking": {"dock_failures": 3}}
            async with console_tour(scenario, site=site, once=False) as (run, _people, url):
                exe = run.executive
                senders: list[tuple[str, bool, str]] = []
                listen(exe, lambda e: senders.append((e.command, e.ok, e.by)), OperatorDone)
                book = exe.staff.book
                await run.executive_ticks_until(lambda: "docking_failed" in book.active, 120)
                async with aiohttp.ClientSession() as s:
                    async with s.get(f"{url}/api/state") as r:
                        state = await r.json()
                    await run.executive_ticks_until(  # told again while nobody answers
                        lambda: any(g.body.get("repeat", 0) >= 1 for g in hook.got), 120
                    )
                    refused = await command(s, url, {"command": "done_by_hand"})
                    docking = run.sim.world.docking  # a person puts the robot on its charger
                    docking.state, docking.docked = "docked", True
                    await run.executive_ticks_until(lambda: _docked(exe), 30)
                    done = await command(s, url, {"command": "done_by_hand"})
                    await run.executive_ticks_until(lambda: "docking_failed" not in book.active)
                    async with s.get(f"{url}/api/state") as r:
                        after = await r.json()
                await run.executive_ticks_until(
                    lambda: any(g.body.get("state") == "cleared" for g in hook.got), 30
                )
                exe.stop("test over")
                return {
                    "senders": senders,
                    "state": state,
                    "refused": refused,
                    "done": done,
                    "after": after,
                    "got": [g.body for g in hook.got],
                }

    out = asyncio.run(main())
    assert out["senders"] == [("done_by_hand", False, "console"), ("done_by_hand", True, "console")]
    help_ = out["state"]["help"]
    assert help_["what"] == (  # in the site's language (config/site.yaml: es)
        "El robot no ha conseguido acoplarse a su cargador tras varios intentos."
    )
    assert help_["answers"] == ["retry", "done_by_hand", "service_off"]
    assert isinstance(help_["since"], float)
    assert out["refused"][0] == 409 and "not on its charger" in out["refused"][1]["reason"]
    assert out["done"][0] == 200 and out["done"][1]["ok"] is True
    assert out["after"]["help"] is None
    states = [(g["id"], g["state"], g.get("repeat", 0)) for g in out["got"]]
    assert states[0] == ("docking_failed", "raised", 0)
    assert ("docking_failed", "raised", 1) in states  # escalated once, a minute on
    assert states[-1][:2] == ("docking_failed", "cleared")
    assert "done_by_hand" in out["got"][0]["answers"]


def _docked(exe: Any) -> bool:
    from frog_bt.model import keys

    reading = exe.core.board.get(keys.DOCKING)
    return reading is not None and reading.value == "docked"
