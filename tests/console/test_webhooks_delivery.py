"""How alert changes travel, as they will fail: one task per URL (a dead receiver delays
nobody), no redirect followed, URLs redacted in every log line, bodies bounded, and the
site configuration's destinations checked with errors naming the path."""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path
from typing import Any

import pytest
import yaml
from aiohttp import web
from receivers import Receiver, closed_port

from frog_bt.config import DEFAULT_CONFIG, AlertsCfg, load_site
from frog_bt.errors import ConfigError
from frog_bt.live.console.webhooks import ANSWER_MAX, Webhooks, redact
from frog_bt.model.channels import Alert
from frog_bt.runtime.alerts import AlertBook, Facts

SECRETS = ("s3cretpass", "K3YVALUE", "hunter")


def alert(n: int, text: str = "The battery is low. Charge it.") -> Alert:
    return Alert(f"a{n}", "battery_low", text, "raised", float(n))


def hooks_for(*urls: object, **more: Any) -> Webhooks:
    return Webhooks(AlertsCfg.model_validate({"webhooks": list(urls), **more}))


def test_a_dead_receiver_delays_nobody_else() -> None:
    async def main() -> tuple[list[str], int, int]:
        async with Receiver(fail_first=10**6) as dead, Receiver() as healthy:
            # one queue for all would hold the healthy receiver ~30 s per alert
            hooks = hooks_for(
                f"{dead.url}/hook",
                f"http://127.0.0.1:{closed_port()}/x",
                f"{healthy.url}/hook",
                webhook_backoff=30.0,
                webhook_attempts=5,
            )
            hooks.start()
            for n in range(3):
                hooks.notify(0.0, alert(n))
            got = await healthy.wait_for(3, within=5.0)
            calls, retried = dead.calls, hooks.stats.retried
            await hooks.finish(timeout=0.1)
            return [g.body["id"] for g in got], calls, retried

    ids, dead_calls, retried = asyncio.run(main())
    assert ids == ["a0", "a1", "a2"]  # in order, while the others wait to retry
    assert dead_calls == 1 and retried >= 2  # the dead one and the closed port each wait


def test_a_redirect_is_not_followed_and_is_a_failure(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> tuple[int, int, int]:
        async with Receiver() as target, Receiver() as bouncer:
            bouncer.answer = lambda _r: web.Response(
                status=307, headers={"Location": f"{target.url}/stolen"}
            )
            hooks = hooks_for(f"{bouncer.url}/hook", webhook_backoff=0.01)
            hooks.start()
            hooks.notify(0.0, alert(1))
            await bouncer.wait_calls(1)
            await hooks.finish()
            return target.calls, bouncer.calls, hooks.stats.failed

    with caplog.at_level(logging.INFO, logger="frog_bt"):
        target_calls, bouncer_calls, failed = asyncio.run(main())
    assert target_calls == 0  # the body went nowhere else
    assert bouncer_calls == 1 and failed == 1  # not retried either
    assert "HTTP 307 (redirects are not followed)" in caplog.text


def test_urls_are_redacted_in_every_log_line(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> tuple[str, str]:
        async with Receiver(fail_first=10**6) as failing:
            port = failing.url.rsplit(":", 1)[1]
            secret = f"http://user:s3cretpass@127.0.0.1:{port}/hook/hunter2?key=K3YVALUE"
            down = f"http://user:s3cretpass@127.0.0.1:{closed_port()}/x?key=K3YVALUE"
            refusing = Receiver(fail_first=10**6, fail_status=403)
            async with refusing:
                rport = refusing.url.rsplit(":", 1)[1]
                hooks = hooks_for(
                    secret,
                    down,
                    f"{refusing.url}/h?key=K3YVALUE",
                    {"url": f"http://u:hunter3@127.0.0.1:{rport}/t0pic", "format": "ntfy"},
                    webhook_backoff=0.01,
                    webhook_attempts=2,
                )
                hooks.start()
                hooks.notify(0.0, alert(1))
                await hooks.finish(timeout=5.0)
            return f"http://127.0.0.1:{port}", f"http://127.0.0.1:{rport}"

    with caplog.at_level(logging.DEBUG):
        failing_url, refusing_url = asyncio.run(main())
    text = caplog.text
    assert f"webhook {failing_url}: HTTP 503; try 2 of 2" in text
    assert f"webhook {refusing_url} refused alert a1: HTTP 403" in text
    assert "not delivered after 2 tries (ClientConnectorError" in text
    for secret in (*SECRETS, "user:", "key="):
        assert secret not in text


@pytest.mark.parametrize(
    "url, shown",
    [
        ("https://user:pass@hooks.example:8443/p/a/t/h?key=1#f", "https://hooks.example:8443"),
        ("http://127.0.0.1/x", "http://127.0.0.1"),
        ("http://[::1]:9093/api", "http://[::1]:9093"),
        ("http://host:notaport/", "<a malformed URL>"),
        ("no url at all", "<a malformed URL>"),
    ],
)
def test_redact(url: str, shown: str) -> None:
    assert redact(url) == shown


def test_bodies_sent_and_answers_read_are_bounded() -> None:
    async def main() -> tuple[int, int]:
        async with Receiver() as r:
            r.answer = lambda _r: web.Response(status=200, body=b"x" * (ANSWER_MAX * 256))
            hooks = hooks_for(f"{r.url}/hook")
            hooks.start()
            hooks.notify(0.0, alert(1, text="<b>" + "overheated " * 20_000))  # from /diagnostic
            [got] = await r.wait_for(1)
            await hooks.finish()
            return len(got.body["text"]), hooks.stats.posted

    text_length, posted = asyncio.run(main())
    assert text_length == 1000 and posted == 1


def test_an_alertmanager_destination_resends_its_firing_alerts() -> None:
    async def main() -> list[tuple[str, str]]:
        async with Receiver() as r:
            hooks = hooks_for({"url": r.url, "format": "alertmanager"})
            [destination] = hooks.destinations
            destination.refresh = 0.05  # wall seconds here; a minute on a robot
            book = AlertBook(hooks.cfg)
            book.listeners.append(hooks.notify)
            hooks.start()
            book.update(Facts(now=0.0, battery=5.0))
            await r.wait_for(3)  # raised, then re-sent twice
            book.update(Facts(now=1.0))
            got = await r.wait_for(4)
            await hooks.finish()
            return [
                (g.body[0]["labels"]["kind"], g.body[0]["annotations"]["summary"]) for g in got[:3]
            ]

    assert asyncio.run(main()) == [("battery_low", "The battery is at 5%.")] * 3


@pytest.mark.parametrize(
    "hooks, path, says",
    [
        (["ftp://x/y"], "alerts.webhooks[0]", "expected an http:// or https:// URL"),
        (
            [{"url": "https://ntfy.sh", "format": "ntfy"}],
            "alerts.webhooks[0]",
            "an ntfy URL names its topic",
        ),
        ([{"url": "https://x", "format": "slack"}], "alerts.webhooks[0].format", "got 'slack'"),
        (
            ["https://ok", {"url": "http://u:hunter2@h:99999/x"}],
            "alerts.webhooks[1]",
            "expected an http:// or https:// URL",
        ),
        ([{"url": "https://x", "topic": "t"}], "alerts.webhooks[0].topic", "unknown key"),
    ],
)
def test_destinations_are_checked_with_the_path(
    tmp_path: Path, hooks: list[object], path: str, says: str
) -> None:
    site = tmp_path / "site.yaml"
    data = yaml.safe_load(DEFAULT_CONFIG.read_text())
    data["alerts"] = {"webhooks": hooks}
    site.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError) as error:
        load_site(site)
    message = str(error.value)
    assert path in message and says in message, message
    assert "hunter2" not in message


def test_a_plain_url_is_json_and_console_url_is_checked() -> None:
    cfg = AlertsCfg.model_validate(
        {"webhooks": ["https://x/h"], "console_url": "https://frog.example/"}
    )
    assert cfg.webhooks[0].format == "json" and cfg.console_url == "https://frog.example"
    with pytest.raises(ValueError, match="no user, password, query or fragment"):
        AlertsCfg(console_url="https://frog.example/?token=x")
