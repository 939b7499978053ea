"""The robot asks for help: an alert is raised once, reaches a webhook (retried when the
receiver fails), is cleared when its condition ends and is acknowledged by a person."""

from __future__ import annotations

import asyncio
import json

import aiohttp
from aiohttp import web
from console_tour import command, console_tour
from test_faults import is_

from frog_bt.config import AlertsCfg, load_site
from frog_bt.model.help import Help, HelpAbout
from frog_bt.runtime.alerts import AlertBook, Facts, conditions


async def receiver(fail_first: int) -> tuple[web.AppRunner, str, list[dict[str, object]]]:
    """A phone-notification service on 127.0.0.1 that answers 503 ``fail_first`` times."""
    got: list[dict[str, object]] = []
    calls = [0]

    async def hook(request: web.Request) -> web.Response:
        calls[0] += 1
        if calls[0] <= fail_first:
            return web.Response(status=503)
        got.append(json.loads(await request.read()))
        return web.Response(status=204)

    app = web.Application()
    app.router.add_post("/hook", hook)
    runner = web.AppRunner(app)
    await runner.setup()
    site = web.TCPSite(runner, "127.0.0.1", 0)
    await site.start()
    port = runner.addresses[0][1]
    return runner, f"http://127.0.0.1:{port}/hook", got


def test_a_low_battery_alert_reaches_the_webhook_after_a_retry_is_cleared_and_acked() -> None:
    async def main() -> tuple[list[dict[str, object]], list[str], list[str], int, int]:
        runner, url, got = await receiver(fail_first=1)
        site = load_site()
        site = site.model_copy(
            update={
                "alerts": site.alerts.model_copy(
                    update={"webhooks": [url], "webhook_backoff": 0.05}
                )
            }
        )
        try:
            async with console_tour(site=site, once=False) as (run, people, curl):
                await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
                run.sim.world.battery.percentage = 22.0  # below alerts.battery_below (25)
                book = run.executive.staff.book
                await run.executive_ticks_until(lambda: "battery_low" in book.active)
                await run.executive_ticks_until(lambda: len(got) == 1, wall=30)
                raised = [a.state for a in book.shown()]
                run.sim.world.battery.percentage = 80.0  # charged again: the condition ends
                await run.executive_ticks_until(lambda: "battery_low" not in book.active)
                shown = [a.state for a in book.shown()]  # cleared, still shown until acked
                async with aiohttp.ClientSession() as s:
                    status, _ = await command(
                        s, curl, {"command": "ack_alert", "id": "battery_low"}
                    )
                await run.executive_ticks_until(lambda: len(got) == 3, wall=30)
                run.executive.stop("test over")
                return got, raised, shown, status, people.webhooks.stats.retried
        finally:
            await runner.cleanup()

    got, raised, shown, status, retried = asyncio.run(main())
    assert [(g["id"], g["state"]) for g in got] == [
        ("battery_low", "raised"),
        ("battery_low", "cleared"),
        ("battery_low", "acknowledged"),
    ]
    # the site speaks Spanish (config/site.yaml language: es): so do its webhooks
    assert got[0]["text"] == (
        "Al robot le queda un 22 % de batería. "
        "Asegúrese de que el robot puede llegar a su cargador."
    )
    assert raised == ["raised"] and shown == ["cleared"] and status == 200
    assert retried == 1  # the first POST got a 503 and was tried again


def test_each_condition_in_plain_words_and_raised_once() -> None:
    cfg = AlertsCfg()
    book = AlertBook(cfg)
    facts = Facts(
        now=1000.0,
        battery=50.0,
        faults=("motors: overheated",),
        rosbridge_down_since=900.0,
        frontend_silent_since=990.0,
        seeking_since=0.0,
        help=Help(HelpAbout.DOCK, 900.0),
        gave_up="dock failed",
        stops_given_up=("POI3",),
        pause_ran_out=True,
    )
    kinds = [c.kind for c in conditions(facts, cfg)]
    assert kinds == [
        "docking_failed",
        "stop_given_up",
        "fault",
        "rosbridge_down",
        "no_visitor",
        "pause_ran_out",
    ]  # front end silent for 10 s: not yet
    assert len(book.update(facts)) == 6
    assert book.update(facts) == []  # raised once
    later = Facts(now=1100.0, frontend_silent_since=990.0)
    changes = book.update(later)
    assert [(a.kind, a.state) for a in changes] == [
        ("frontend_silent", "raised"),
        ("docking_failed", "cleared"),
        ("stop_given_up", "cleared"),
        ("fault", "cleared"),
        ("rosbridge_down", "cleared"),
        ("no_visitor", "cleared"),
        ("pause_ran_out", "cleared"),
    ]
    assert all(c.text.endswith(".") and ". " in c.text for c in conditions(facts, cfg))
