"""The token: throttled failures logged once a minute (by hand-moved time), one-use
stream tickets that expire, reads off loopback closed without a header or a ticket (the
token never in a URL), and the token file's length, characters and permissions."""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path

import aiohttp
import pytest
from console_tour import TOKEN, auth, console_tour
from test_faults import is_

from frog_bt.commands.console_options import console_settings
from frog_bt.errors import UsageError
from frog_bt.live.console.bearer import Tickets, bearer
from frog_bt.live.console.server import ACCESS
from frog_bt.live.console.throttle import FAIL_BURST, FAIL_EVERY, TOTAL_BURST, Failures


class Hand:
    """A clock moved by hand."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def test_only_bearer_and_any_bytes() -> None:
    assert bearer(f"Bearer {TOKEN}") == TOKEN.encode() and bearer(f"bearer  {TOKEN} ")
    assert bearer(f"Basic {TOKEN}") is None and bearer(TOKEN) is None and bearer("Bearer ") is None
    assert bearer("Bearer \udcff\udcfe") == b"\xff\xfe"  # aiohttp's undecodable bytes


def test_failures_are_throttled_per_client_and_in_total_and_every_one_logged(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = Hand()
    failures = Failures(clock)
    caplog.set_level(logging.WARNING, "frog_bt.live.console.throttle")
    assert [failures.failed("10.0.0.5") for _ in range(FAIL_BURST + 3)] == [False] * (
        FAIL_BURST
    ) + [True] * 3
    assert not failures.failed("10.0.0.6")  # another client: its own budget
    clock.t += FAIL_EVERY
    assert not failures.failed("10.0.0.5")  # one more try after a while
    clock.t += 30.0
    failures.flush()
    clock.t += 30.0
    failures.flush()
    failures.flush()
    assert [r.getMessage() for r in caplog.records] == [
        "console: 1 failed token attempt, 0 of them answered 429 (from 10.0.0.5 1)",
        "console: 14 failed token attempts, 3 of them answered 429 (from 10.0.0.5 13, 10.0.0.6 1)",
    ]
    assert failures.counted == 15
    # many clients at once: the total budget answers 429 too, each client fresh
    spread = [failures.failed(f"10.1.{i // 256}.{i % 256}") for i in range(TOTAL_BURST + 20)]
    assert spread.count(True) >= 20 - 1


def test_tickets_are_used_once_and_expire() -> None:
    clock = Hand()
    tickets = Tickets(clock, ttl=30.0)
    one, two = tickets.issue(), tickets.issue()
    assert one != two and TOKEN not in one
    assert tickets.spend(one) and not tickets.spend(one)
    clock.t = 31.0
    assert not tickets.spend(two) and not tickets.spend("made-up")


def test_off_loopback_reads_need_a_header_or_a_ticket_never_the_token_in_a_url() -> None:
    async def main() -> list[object]:
        async with console_tour() as (run, people, url):
            assert people.console is not None
            people.console.app[ACCESS].loopback = False  # as on 0.0.0.0
            await run.sim.wait_for(is_("tour", state="started"), 60)
            out: list[object] = []
            async with aiohttp.ClientSession() as s:
                for path, headers in (
                    ("/api/state", {}),
                    (f"/api/state?token={TOKEN}", {}),
                    ("/api/state", auth()),
                    ("/", {}),  # the page itself holds no data
                ):
                    async with s.get(f"{url}{path}", headers=headers) as r:
                        out.append(r.status)
                async with s.post(f"{url}/api/ticket", headers=auth()) as r:
                    ticket = (await r.json())["ticket"]
                async with s.ws_connect(f"{url}/api/stream?ticket={ticket}") as ws:
                    out.append("phase" in await ws.receive_json())
                for query in (f"?ticket={ticket}", f"?token={TOKEN}"):  # spent; no token in URLs
                    with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                        await s.ws_connect(f"{url}/api/stream{query}")
                    out.append(refused.value.status)
                async with s.get(f"{url}/api/state", headers={"X-Forwarded-For": "10.1.1.1"}) as r:
                    out.append(r.status)
            run.executive.stop("test over")
            return out

    assert asyncio.run(main()) == [401, 401, 200, 200, True, 401, 401, 401]


def test_the_token_file_is_bounded_visible_ascii_and_private(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "token"

    class Args:
        console = "127.0.0.1:8080"
        console_token_file = path

    def settings(text: str, mode: int = 0o600) -> str | None:
        path.write_text(text)
        path.chmod(mode)
        got = console_settings(Args())  # type: ignore[arg-type]
        return got.token if got is not None else None

    for bad, why in (
        ("x" * 15, "16 to 512 characters, found 15"),
        ("x" * 513, "16 to 512 characters, found 513"),
        ("sixteen chars ok", "visible ASCII"),
        ("sixteen-chars-é-x", "visible ASCII"),
    ):
        with pytest.raises(UsageError, match=why):
            settings(bad)
    assert settings("x" * 16) == "x" * 16 and settings("y" * 512 + "\n") == "y" * 512
    assert not caplog.records
    assert settings(TOKEN, 0o644) == TOKEN  # used, with the fix in one line
    assert [r.getMessage() for r in caplog.records] == [
        f"--console-token-file {path}: others than its owner may read or change it; "
        f"fix: chmod 600 {path}"
    ]
