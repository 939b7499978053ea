"""Acknowledging from the phone: a signed link acknowledges exactly its own alert; an
expired, tampered or other alert's link is refused (403) and acknowledges nothing. And
what a notification carries reaches ``/api/state`` redacted."""

from __future__ import annotations

import asyncio
import time
from pathlib import Path
from urllib.parse import quote

import aiohttp
from console_tour import TOKEN, console_tour
from receivers import Receiver

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.live.console.acklink import (
    Verdict,
    ack_link,
    console_id,
    link_key,
    signature,
    verify,
)
from frog_bt.model.events import OperatorDone
from frog_bt.runtime.observer import listen

KEY = link_key(TOKEN)
CONSOLE = "http://127.0.0.1:8080"


# ---------------------------------------------------------------- sans-I/O

AT = "1780302810.200000"


def test_the_key_is_derived_and_the_link_never_holds_the_token() -> None:
    link = ack_link(CONSOLE, KEY, "frog", "stop_given_up:POI3", AT, 2_000_000_000)
    assert link.startswith(f"{CONSOLE}/ack/stop_given_up%3APOI3?at={AT}&exp=2000000000&sig=")
    assert TOKEN not in link and KEY.hex() not in link and TOKEN.encode() != KEY
    assert link_key("another-token-99") != KEY
    assert console_id(TOKEN) not in (KEY.hex(), TOKEN) and len(console_id(TOKEN)) == 16


def test_verify_binds_robot_alert_raise_and_expiry() -> None:
    exp = 1000
    sig = signature(KEY, "frog", "fault", AT, exp)
    assert verify(KEY, "frog", "fault", AT, str(exp), sig, now=999.0) is Verdict.VALID
    assert verify(KEY, "frog", "fault", AT, str(exp), sig, now=1000.0) is Verdict.EXPIRED
    assert verify(KEY, "frog", "fault", AT, str(exp + 3600), sig, 999.0) is Verdict.BAD
    tampered = sig[:-1] + ("0" if sig[-1] != "0" else "1")
    assert verify(KEY, "frog", "fault", AT, str(exp), tampered, now=999.0) is Verdict.BAD
    assert verify(KEY, "frog", "battery_low", AT, str(exp), sig, 999.0) is Verdict.BAD
    assert verify(KEY, "frog-2", "fault", AT, str(exp), sig, 999.0) is Verdict.BAD  # robot
    later = "1780309999.000000"
    assert verify(KEY, "frog", "fault", later, str(exp), sig, 999.0) is Verdict.BAD  # raise
    other = link_key("another-token-99")
    assert verify(other, "frog", "fault", AT, str(exp), sig, 999.0) is Verdict.BAD
    for bad_exp in ("", "-5", "1e9", "\uff11\uff12", "9" * 40):
        assert verify(KEY, "frog", "fault", AT, bad_exp, sig, now=0.0) is Verdict.BAD
    assert verify(KEY, "frog", "fault", AT, str(exp), "ü" * 64, now=0.0) is Verdict.BAD
    assert verify(KEY, "frog", "fault", "9" * 40, str(exp), sig, now=0.0) is Verdict.BAD


# ---------------------------------------------------------------- the route, live


def idle_tree(tmp_path: Path) -> Path:
    path = tmp_path / "idle.yaml"
    path.write_text("root: {type: WaitFrontendIdle}\n")  # the robot waits: alerts only
    return path


def test_a_link_shows_then_acknowledges_its_own_raise_once(tmp_path: Path) -> None:
    """GET shows (in the site's language, Spanish) and changes nothing; only the button's
    POST acknowledges; a link for the first raise fails on the second; a used link fails;
    another robot's, an expired or a tampered link acknowledge nothing."""

    async def main() -> dict[str, object]:
        site = load_site()
        assert site.language == "es"
        tree = load_tree(idle_tree(tmp_path), site)
        faults = [
            {"at": 0, "name": "motors", "level": 2, "message": "overheated", "duration": 60},
            {"at": 300, "name": "motors", "level": 2, "message": "again", "duration": 10**6},
        ]
        async with console_tour({"faults": faults}, tree=tree, once=False) as (run, _p, url):
            run.sim.world.battery.percentage = 22.0
            acks: list[tuple[str, bool, str]] = []
            listen(run.executive, lambda e: acks.append((e.id, e.ok, e.by)), OperatorDone)
            book = run.executive.staff.book
            await run.executive_ticks_until(lambda: {"fault", "battery_low"} <= set(book.active))
            first = book.unacknowledged["fault"].occurrence
            now = int(time.time())
            old = ack_link(url, KEY, "frog", "fault", first, now + 600)
            await run.executive_ticks_until(
                lambda: (
                    book.unacknowledged["fault"].occurrence != first
                    and book.unacknowledged["fault"].state == "raised"
                )
            )
            second = book.unacknowledged["fault"].occurrence
            fine = ack_link(url, KEY, "frog", "fault", second, now + 600)
            tries = {
                "expired": ack_link(url, KEY, "frog", "fault", second, now - 1),
                "tampered": fine[:-2] + ("00" if not fine.endswith("00") else "11"),
                "later": fine.replace(f"exp={now + 600}", f"exp={now + 10**6}"),
                "other alert": fine.replace("/ack/fault?", "/ack/battery_low?"),
                "other robot": ack_link(url, KEY, "frog-2", "fault", second, now + 600),
                "no signature": fine.split("&sig=")[0],
                "earlier raise": old,
                "signed by another token": ack_link(
                    url, link_key("x" * 16), "frog", "fault", second, now + 600
                ),
            }
            out: dict[str, object] = {}
            async with aiohttp.ClientSession() as s:
                async with s.get(fine, allow_redirects=False) as r:
                    out["get"] = (r.status, await r.text(), dict(r.headers))
                out["after get"] = "fault" in book.unacknowledged
                async with s.head(fine) as r:
                    out["head"] = r.status
                for name, link in tries.items():
                    async with s.post(link, allow_redirects=False) as r:
                        out[name] = (r.status, await r.text())
                async with s.get(old) as r:
                    out["get earlier"] = (r.status, await r.text())
                async with s.post(fine, headers={"Origin": "http://127.0.0.2:1"}) as r:
                    out["foreign page"] = r.status
                for name in ("valid", "again"):
                    async with s.post(fine, headers={"Origin": url}) as r:
                        out[name] = (r.status, await r.text())
                async with s.get(fine) as r:
                    out["get used"] = (r.status, await r.text())
            out["shown"] = [a.id for a in book.shown()]
            out["acks"] = acks
            run.executive.stop("test over")
            return out

    out = asyncio.run(main())
    status, page, headers = out["get"]  # type: ignore[misc]
    assert status == 200 and out["after get"] is True  # GET acknowledged nothing
    assert '<form method="post"><button type="submit">Marcar como visto</button></form>' in page
    assert "¿Marcar este aviso como visto?" in page and "Robot frog:" in page
    assert "<script" not in page and 'lang="es"' in page
    assert headers["Content-Security-Policy"] == (
        "default-src 'none'; form-action 'self'; frame-ancestors 'none'"
    )
    assert headers["X-Frame-Options"] == "DENY" and headers["Cache-Control"] == "no-store"
    assert out["head"] == 405
    statuses = {
        name: value[0]  # type: ignore[index]
        for name, value in out.items()
        if isinstance(value, tuple) and name != "get"
    }
    assert statuses == {
        "expired": 403,
        "tampered": 403,
        "later": 403,
        "other alert": 403,
        "other robot": 403,
        "no signature": 403,
        "earlier raise": 409,
        "signed by another token": 403,
        "get earlier": 409,
        "valid": 200,
        "again": 409,
        "get used": 409,
    }
    assert out["foreign page"] == 403
    assert "Este enlace ha caducado" in out["expired"][1]  # type: ignore[index]
    assert "volvió a saltar" in out["earlier raise"][1]  # type: ignore[index]
    assert "Este enlace ya se usó" in out["again"][1]  # type: ignore[index]
    assert out["shown"] == ["battery_low"]  # only the fault was acknowledged
    assert out["acks"] == [("fault", True, "link")]  # once, recorded as by the link


def test_notification_urls_never_reach_api_state(tmp_path: Path) -> None:
    async def main() -> tuple[str, int]:
        async with Receiver(fail_first=10**6) as failing:
            port = failing.url.rsplit(":", 1)[1]
            site = load_site()
            site = site.model_copy(
                update={
                    "alerts": site.alerts.model_copy(
                        update={
                            "webhooks": type(site.alerts)
                            .model_validate(
                                {
                                    "webhooks": [
                                        f"http://frog:s3cretpass@127.0.0.1:{port}/h?key=K3YVALUE",
                                    ]
                                }
                            )
                            .webhooks,
                            "webhook_backoff": 0.01,
                            "webhook_attempts": 2,
                        }
                    )
                }
            )
            tree = load_tree(idle_tree(tmp_path), site)
            async with console_tour(site=site, tree=tree, once=False) as (run, people, url):
                run.sim.world.battery.percentage = 22.0
                await run.executive_ticks_until(lambda: people.webhooks.stats.failed == 1, wall=30)
                async with aiohttp.ClientSession() as s:
                    async with s.get(f"{url}/api/state") as r:
                        text = await r.text()
                    async with s.get(f"{url}/ack/{quote('battery_low')}") as r:
                        assert r.status == 403
                run.executive.stop("test over")
                return text, failing.calls

    state, calls = asyncio.run(main())
    assert calls == 2
    assert f"webhook http://127.0.0.1:{port_of(state)}: alert battery_low not delivered" in state
    for secret in ("s3cretpass", "K3YVALUE", "frog:", "key="):
        assert secret not in state


def port_of(state: str) -> str:
    return state.split("webhook http://127.0.0.1:", 1)[1].split(":", 1)[0]
