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
from frog_bt.live.console.acklink import Verdict, ack_link, link_key, signature, verify
from frog_bt.model.events import OperatorDone
from frog_bt.runtime.observer import listen

KEY = link_key(TOKEN)
CONSOLE = "http://127.0.0.1:8080"


# ---------------------------------------------------------------- sans-I/O


def test_the_key_is_derived_and_the_link_never_holds_the_token() -> None:
    link = ack_link(CONSOLE, KEY, "stop_given_up:POI3", 2_000_000_000)
    assert link.startswith(f"{CONSOLE}/ack/stop_given_up%3APOI3?exp=2000000000&sig=")
    assert TOKEN not in link and KEY.hex() not in link and TOKEN.encode() != KEY
    assert link_key("another-token-99") != KEY


def test_verify_valid_expired_tampered_and_other_alert() -> None:
    exp = 1000
    sig = signature(KEY, "fault", exp)
    assert verify(KEY, "fault", str(exp), sig, now=999.0) is Verdict.VALID
    assert verify(KEY, "fault", str(exp), sig, now=1000.0) is Verdict.EXPIRED
    assert verify(KEY, "fault", str(exp + 3600), sig, now=999.0) is Verdict.BAD  # later exp
    tampered = sig[:-1] + ("0" if sig[-1] != "0" else "1")
    assert verify(KEY, "fault", str(exp), tampered, now=999.0) is Verdict.BAD
    assert verify(KEY, "battery_low", str(exp), sig, now=999.0) is Verdict.BAD  # other alert
    assert verify(link_key("another-token-99"), "fault", str(exp), sig, 999.0) is Verdict.BAD
    for bad_exp in ("", "-5", "1e9", "\uff11\uff12", "9" * 40):
        assert verify(KEY, "fault", bad_exp, sig, now=0.0) is Verdict.BAD
    assert verify(KEY, "fault", str(exp), "ü" * 64, now=0.0) is Verdict.BAD


# ---------------------------------------------------------------- the route, live


def idle_tree(tmp_path: Path) -> Path:
    path = tmp_path / "idle.yaml"
    path.write_text("root: {type: WaitFrontendIdle}\n")  # the robot waits: alerts only
    return path


def test_a_signed_link_acknowledges_exactly_its_alert_and_bad_ones_nothing(tmp_path: Path) -> None:
    async def main() -> tuple[list[tuple[str, int, str]], list[str], dict[str, object]]:
        site = load_site()
        tree = load_tree(idle_tree(tmp_path), site)
        fault = {"at": 0, "name": "motors", "level": 2, "message": "overheated", "duration": 10**6}
        async with console_tour({"faults": [fault]}, tree=tree, once=False) as (run, _people, url):
            run.sim.world.battery.percentage = 22.0
            acks: list[tuple[str, bool, str]] = []
            listen(run.executive, lambda e: acks.append((e.id, e.ok, e.by)), OperatorDone)
            book = run.executive.staff.book
            await run.executive_ticks_until(lambda: {"fault", "battery_low"} <= set(book.active))
            now = int(time.time())
            fine = ack_link(url, KEY, "fault", now + 600)
            exp, sig = fine.split("?")[1].split("&")
            tries = {
                "expired": ack_link(url, KEY, "fault", now - 1),
                "tampered": fine[:-2] + ("00" if not fine.endswith("00") else "11"),
                "later": fine.replace(f"exp={now + 600}", f"exp={now + 10**6}"),
                "other alert": f"{url}/ack/battery_low?{exp}&{sig}",
                "no signature": f"{url}/ack/fault?{exp}",
                "signed by another token": ack_link(url, link_key("x" * 16), "fault", now + 600),
                "valid": fine,
                "again": fine,
            }
            out = []
            async with aiohttp.ClientSession() as s:
                for name, link in tries.items():
                    async with s.get(link, allow_redirects=False) as r:
                        out.append((name, r.status, await r.text()))
                        headers = dict(r.headers)
                async with s.head(fine) as r:
                    assert r.status == 405  # a HEAD acknowledges nothing
            shown = [a.id for a in book.shown()]
            run.executive.stop("test over")
            assert ("fault", True, "link") in acks  # recorded as acknowledged by the link
            return out, shown, headers

    out, shown, headers = asyncio.run(main())
    statuses = {name: status for name, status, _ in out}
    assert statuses == {
        "expired": 403,
        "tampered": 403,
        "later": 403,
        "other alert": 403,
        "no signature": 403,
        "signed by another token": 403,
        "valid": 200,
        "again": 409,
    }
    pages = {name: page for name, _, page in out}
    assert "This link has expired: nothing was acknowledged." in pages["expired"]
    assert "This link is not valid: nothing was acknowledged." in pages["other alert"]
    assert "Done: alert fault acknowledged." in pages["valid"]
    assert "Not done: no alert &#x27;fault&#x27; to acknowledge." in pages["again"]
    assert all("<script" not in page for page in pages.values())
    assert shown == ["battery_low"]  # only the fault was acknowledged
    assert headers["Content-Type"].startswith("text/html")
    assert headers["Content-Security-Policy"].startswith("default-src 'none'")


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
