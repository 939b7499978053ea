"""A flood of wrong tokens cannot lock staff out: every right-token command goes through
while it lasts, every failure is counted in the log, and failures are throttled per client
(behind a trusted proxy, the client ``X-Forwarded-For`` names) and in total."""

from __future__ import annotations

import asyncio
import logging
import re
from pathlib import Path

import aiohttp
import pytest
from console_tour import TOKEN, auth, console_tour
from test_faults import is_

from frog_bt.cli import main
from frog_bt.live.console.server import ACCESS
from frog_bt.live.console.throttle import FAIL_BURST, LOG_EVERY, client_of, networks

PROXY = networks(["127.0.0.1", "10.0.0.0/8"])


def test_the_client_is_the_connection_unless_a_trusted_proxy_names_another() -> None:
    assert client_of("127.0.0.1", ["203.0.113.9"], ()) == "127.0.0.1"  # no proxy trusted
    assert client_of("192.0.2.7", ["203.0.113.9"], PROXY) == "192.0.2.7"  # not a proxy
    assert client_of("127.0.0.1", ["203.0.113.9"], PROXY) == "203.0.113.9"
    # a client's own X-Forwarded-For is not believed: the rightmost untrusted hop counts
    assert client_of("127.0.0.1", ["6.6.6.6, 203.0.113.9, 10.1.2.3"], PROXY) == "203.0.113.9"
    assert client_of("127.0.0.1", ["6.6.6.6", "203.0.113.9"], PROXY) == "203.0.113.9"
    assert client_of("127.0.0.1", ["junk<script>"], PROXY) == "127.0.0.1"  # never shown
    assert client_of("127.0.0.1", [], PROXY) == "127.0.0.1"
    assert client_of("127.0.0.1", ["[2001:db8::1]:443"], PROXY) == "2001:db8::1"


def test_a_flood_of_wrong_tokens_never_refuses_a_right_one(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, capsys: pytest.CaptureFixture[str]
) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN)
    caplog.set_level(logging.WARNING, "frog_bt.live.console.throttle")

    async def main_() -> tuple[list[int], dict[int, int], int]:
        async with console_tour(once=False) as (run, people, url):
            assert people.console is not None
            failures = people.console.app[ACCESS].failures
            wall = [0.0]
            failures.clock = lambda: wall[0]  # the summary's minute, moved by hand
            await run.sim.wait_for(is_("tour", state="started"), 60)
            flooding = True
            answers: dict[int, int] = {}

            async def flood() -> None:  # behind a proxy: everyone is 127.0.0.1
                async with aiohttp.ClientSession() as s:
                    while flooding:
                        async with s.post(
                            f"{url}/api/command", json={"command": "home"}, headers=auth("x" * 20)
                        ) as r:
                            answers[r.status] = answers.get(r.status, 0) + 1

            task = asyncio.create_task(flood())
            codes = []
            for command in ("pause", "resume") * 3:
                while sum(answers.values()) < FAIL_BURST * (len(codes) + 2):
                    await asyncio.sleep(0.01)  # the flood is on and over its budget
                argv = ["ctl", command, "--console", url, "--token-file", str(token)]
                codes.append(await asyncio.to_thread(main, [*argv, "--timeout", "60"]))
            flooding = False
            await task
            wall[0] += LOG_EVERY
            failures.flush()
            run.executive.stop("test over")
            return codes, answers, failures.counted

    codes, answers, counted = asyncio.run(main_())
    assert codes == [0] * 6, capsys.readouterr()  # every right-token command done
    assert answers[429] > 0 and answers[401] >= FAIL_BURST  # the flood was throttled
    sent = sum(answers.values())
    assert counted == sent
    lines = [r.getMessage() for r in caplog.records if "failed token attempt" in r.getMessage()]
    logged = [re.match(r"console: (\d+) failed token attempts?, (\d+) of them", m) for m in lines]
    assert sum(int(m.group(1)) for m in logged if m) == sent  # every failure in the log
    assert sum(int(m.group(2)) for m in logged if m) == answers[429]


def test_behind_a_trusted_proxy_each_client_has_its_own_budget() -> None:
    async def main_() -> dict[str, list[int]]:
        async with console_tour(once=False) as (run, people, url):
            assert people.console is not None
            access = people.console.app[ACCESS]
            out: dict[str, list[int]] = {}
            async with aiohttp.ClientSession() as s:

                async def post(xff: str, n: int, **headers: str) -> list[int]:
                    statuses = []
                    for _ in range(n):
                        async with s.post(
                            f"{url}/api/command",
                            json={"command": "resume"},
                            headers={"X-Forwarded-For": xff, **headers},
                        ) as r:
                            statuses.append(r.status)
                    return statuses

                out["untrusted"] = await post("203.0.113.9", FAIL_BURST + 1)
                out["untrusted other"] = await post("203.0.113.10", 1)  # same client
                access.proxies = networks(["127.0.0.1"])
                access.failures.buckets.clear()
                out["attacker"] = await post("203.0.113.9", FAIL_BURST + 1)
                out["other client"] = await post("203.0.113.10", 1)
                out["spoofed"] = await post("203.0.113.10, 203.0.113.9", 1)  # still .9
                out["staff"] = await post("203.0.113.9", 1, **auth())  # the right token
            run.executive.stop("test over")
            return out

    out = asyncio.run(main_())
    assert out["untrusted"] == [401] * FAIL_BURST + [429]
    assert out["untrusted other"] == [429]  # X-Forwarded-For not read: the same client
    assert out["attacker"] == [401] * FAIL_BURST + [429]
    assert out["other client"] == [401]  # its own budget
    assert out["spoofed"] == [429]
    assert out["staff"] == [409]  # through (nothing to resume), whatever the failures
