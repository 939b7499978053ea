"""A shift handed over (``staff.handover``): composed at a configured time on the project
clock (sim time) with the day's figures — checked against what the day's own records
say — sent to the webhooks (the generic JSON and ntfy; not to Alertmanager), in the
site's language, shown on the page as *Relevo*, and composed again on demand."""

from __future__ import annotations

import asyncio
from datetime import datetime, time
from typing import Any

import aiohttp
import pytest
from console_tour import auth, command, console_tour
from receivers import Receiver
from test_spanish_help_path import english

from frog_bt.clock import SITE_TZ
from frog_bt.config import load_site
from frog_bt.errors import ConfigError
from frog_bt.live.console.server import SHOWN
from frog_bt.live.console.shift import next_time
from frog_bt.model import keys
from frog_bt.model.events import AlertChanged, OperatorDone
from frog_bt.model.frontend import Tour
from frog_bt.runtime.observer import listen
from frog_bt.yamlfile import validate

HANDOVER_AT = "11:00"  # the default scenario starts at 10:30; the first tour ends near 10:42


def test_a_handover_at_a_configured_time_holds_the_days_figures() -> None:
    async def main() -> dict[str, Any]:
        async with Receiver() as json_hook, Receiver() as ntfy_hook:
            site = load_site()
            alerts = site.alerts.model_copy(
                update={
                    "webhooks": [
                        json_hook.url,
                        {"url": f"{ntfy_hook.url}/frog-staff", "format": "ntfy"},
                    ]
                }
            )
            staff = site.staff.model_copy(update={"handover": [time(11, 0), time(20, 0)]})
            site = site.model_copy(update={"alerts": alerts, "staff": staff})
            scenario = {"docking": {"dock_failures": 3}}
            async with console_tour(scenario, site=site, once=False) as (run, people, url):
                exe = run.executive
                done: list[OperatorDone] = []
                changes: list[AlertChanged] = []
                listen(exe, done.append, OperatorDone)
                listen(exe, changes.append, AlertChanged)
                assert people.console is not None
                shift = people.console.app[SHOWN].shift
                board = exe.core.board
                async with aiohttp.ClientSession() as s:
                    # the first tour ends with three failed docks: the robot asks
                    await run.executive_ticks_until(lambda: board.get(keys.HELP) is not None, 120)
                    retry = await command(s, url, {"command": "retry"})
                    await run.executive_ticks_until(lambda: board.get(keys.HELP) is None, 60)
                    off = await command(s, url, {"command": "service_off"})
                    await run.executive_ticks_until(lambda: board.get(keys.IN_SERVICE) is False)
                    on = await command(s, url, {"command": "service_on"})
                    await run.executive_ticks_until(lambda: board.get(keys.IN_SERVICE) is True)
                    assert shift.last is None, "composed before its time"
                    await run.executive_ticks_until(lambda: shift.last is not None, 120)
                    scheduled = shift.last
                    async with s.get(f"{url}/api/state") as r:
                        state = await r.json()
                    await json_hook.wait_for(1)
                    await ntfy_hook.wait_for(1)
                    # on demand, as the page's button does: the next shift starts empty
                    async with s.post(f"{url}/api/handover") as r:
                        unsigned = r.status
                    async with s.post(f"{url}/api/handover?lang=es", headers=auth()) as r:
                        asked = (r.status, await r.json())
                    await json_hook.wait_for(2)
                exe.stop("test over")
                return {
                    "scheduled": scheduled,
                    "sent": list(run.sent),
                    "done": done,
                    "changes": changes,
                    "answers": (retry, off, on),
                    "state": state,
                    "json": [g.body for g in json_hook.got],
                    "ntfy": [g.body for g in ntfy_hook.got],
                    "unsigned": unsigned,
                    "asked": asked,
                }

    out = asyncio.run(main())
    assert [a[0] for a in out["answers"]] == [200, 200, 200]
    h = out["scheduled"]
    # composed at the configured time, on the project clock (the first tick after it)
    at = datetime.fromtimestamp(h.at, SITE_TZ)
    assert at.strftime("%H:%M") == HANDOVER_AT and h.asked_by == ""

    # the tours: as the tour messages sent to the front end until then say
    tours = [m.state for t, m in out["sent"] if isinstance(m, Tour) and t <= h.at]
    assert h.tours == {
        "started": tours.count("started"),
        "completed": tours.count("ended"),
        "aborted": tours.count("aborted"),
    }
    assert h.tours["started"] >= 1 and h.tours["completed"] >= 1

    # the help request: raised with the alert, answered by the console's retry
    raised = [
        c.t for c in out["changes"] if c.alert.id == "docking_failed" and c.alert.state == "raised"
    ]
    retried = [d.t for d in out["done"] if d.command == "retry" and d.ok]
    assert len(h.asked) == 1
    help_ = h.asked[0]
    assert help_.about == "dock" and help_.by == "console" and help_.answer == "retry"
    assert abs(help_.since - raised[0]) < 1.0
    assert retried[0] <= help_.answered <= retried[0] + 1.0
    # out of service: from the service_off to the service_on, both from the console
    [off_at] = [d.t for d in out["done"] if d.command == "service_off" and d.ok]
    [on_at] = [d.t for d in out["done"] if d.command == "service_on" and d.ok]
    [period] = h.out_of_service
    assert off_at <= period.since <= off_at + 1.0 and on_at <= period.until <= on_at + 1.0
    assert period.by == "console"
    # alerts still open: raised and not cleared by then, by the alert changes
    latest: dict[str, str] = {}
    for c in out["changes"]:
        if c.t <= h.at:
            latest[c.alert.id] = c.alert.state
    assert sorted(a.id for a in h.alerts) == sorted(i for i, s in latest.items() if s != "cleared")

    # the page shows it as Relevo, in Spanish
    shown = out["state"]["handover"]
    assert shown["title"] == f"frog: relevo de las {HANDOVER_AT}"
    lines = [line for sec in shown["sections"] for line in sec["lines"]]
    assert [sec["title"] for sec in shown["sections"]][1:] == [
        "Peticiones de ayuda",
        "Avisos aún abiertos",
        "Fuera de servicio",
        "El robot aún espera",
    ]
    assert any("Respondió «Reintentar» alguien en la consola" in line for line in lines)
    assert any(line.endswith("(lo decidió alguien en la consola)") for line in lines)

    # to the webhooks: the generic JSON and ntfy, in Spanish, with the same figures
    body = next(b for b in out["json"] if b.get("type") == "handover")
    assert body["tours"] == h.tours and body["help"][0]["by"] == "console"
    note = next(b for b in out["ntfy"] if "relevo" in b["title"])
    assert note["topic"] == "frog-staff" and note["title"] == shown["title"]
    for words in (body["text"], body["title"], note["title"], note["message"]):
        assert english(words) == [], words

    # on demand: only with the staff code; the shift since the last handover starts empty
    assert out["unsigned"] == 401
    status, answer = out["asked"]
    assert status == 200 and answer["ok"] is True
    asked_lines = [line for sec in answer["handover"]["sections"] for line in sec["lines"]]
    assert "0 empezadas, 0 completas, 0 terminadas antes de tiempo" in asked_lines
    assert out["json"][-1]["type"] == "handover"


def test_the_next_handover_time_is_local_and_rolls_over_midnight() -> None:
    times = [time(14, 0), time(20, 0)]
    noon = datetime(2026, 6, 1, 12, 0, tzinfo=SITE_TZ).timestamp()
    assert next_time(noon, times, SITE_TZ) == datetime(2026, 6, 1, 14, tzinfo=SITE_TZ).timestamp()
    at_two = datetime(2026, 6, 1, 14, 0, tzinfo=SITE_TZ).timestamp()
    assert next_time(at_two, times, SITE_TZ) == datetime(2026, 6, 1, 20, tzinfo=SITE_TZ).timestamp()
    night = datetime(2026, 6, 1, 21, 0, tzinfo=SITE_TZ).timestamp()
    assert next_time(night, times, SITE_TZ) == datetime(2026, 6, 2, 14, tzinfo=SITE_TZ).timestamp()
    assert next_time(night, [], SITE_TZ) is None


@pytest.mark.parametrize(
    ("given", "error"),
    [
        (["25:00"], "staff.handover[0]: expected a time of day from 00:00 to 23:59, got '25:00'"),
        (["14:00", "14:00"], "staff.handover[1]: 14:00 is given twice"),
        (["2pm"], "staff.handover[0]: expected a local time HH:MM (e.g. \"14:00\"), got '2pm'"),
        ("14:00", "staff.handover: expected a list of local times"),
    ],
)
def test_handover_times_are_checked_up_front(given: Any, error: str) -> None:
    from frog_bt.config import Site
    from frog_bt.resources import site_dir

    data = load_site().model_dump(mode="json", exclude_defaults=True)
    data["staff"] = {"handover": given}
    with pytest.raises(ConfigError) as caught:
        validate(Site, data, site_dir() / "site.yaml", ConfigError)
    assert error in str(caught.value)


def test_yaml_reads_an_unquoted_time_as_that_time() -> None:
    from frog_bt.config import Site

    data = load_site().model_dump(mode="json", exclude_defaults=True)
    data["staff"] = {"handover": [840, "9:05"]}  # YAML 1.1: 14:00 unquoted is 840
    site = validate(Site, data, "site.yaml", ConfigError)
    assert site.staff.handover == [time(9, 5), time(14, 0)]
