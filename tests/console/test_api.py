"""The console's JSON API (CONTRACT §7) on a running simulated tour: the state, every
command and every refusal, auth and bad input."""

from __future__ import annotations

import asyncio
import json
import re
from pathlib import Path

import aiohttp
import pytest
from console_tour import TOKEN, auth, command, console_tour
from test_faults import is_

from frog_bt.commands.console_options import console_settings
from frog_bt.errors import UsageError
from frog_bt.live.console.server import ACCESS
from frog_bt.live.console.throttle import COMMAND_BURST, Rates
from frog_bt.model import keys


def test_state_has_the_contract_fields_and_a_read_needs_no_token_on_loopback() -> None:
    async def main() -> dict[str, object]:
        async with console_tour() as (run, _people, url):
            await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
            async with aiohttp.ClientSession() as s, s.get(f"{url}/api/state") as r:
                assert r.status == 200
                body = await r.json()
            async with aiohttp.ClientSession() as s, s.get(f"{url}/") as r:
                page = await r.text()
            assert "<title>FROG" in page
            assert re.findall(r"https?://", page) == []  # nothing fetched from elsewhere
            return body

    s = asyncio.run(main())
    assert s["phase"] == "Guide a visitor" and s["stop"] == "POI1" and s["visitor"] == 7
    assert isinstance(s["battery"], float) and s["paused"] is False and s["in_service"] is True
    assert s["links"] == {"rosbridge": "connected", "frontend": "acking", "clock": "/clock"}
    assert s["alerts"] == [] and s["tours"] == {"started": 1, "completed": 0, "aborted": 0}


def test_every_command_and_every_refusal() -> None:
    async def main() -> list[tuple[int, dict[str, object]]]:
        async with console_tour(once=False) as (run, people, url):
            assert people.console is not None
            people.console.app[ACCESS].rates = Rates(1000.0)  # not about the rate
            out = []
            async with aiohttp.ClientSession() as s:
                await run.sim.wait_for(is_("tour", state="started"), 60)
                out.append(await command(s, url, {"command": "skip"}))  # nothing to skip
                out.append(await command(s, url, {"command": "resume"}))  # not paused
                await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
                out.append(await command(s, url, {"command": "pause"}))
                out.append(await command(s, url, {"command": "pause"}))
                out.append(await command(s, url, {"command": "resume"}))
                out.append(await command(s, url, {"command": "skip"}))
                out.append(await command(s, url, {"command": "service_off"}))
                out.append(await command(s, url, {"command": "service_on"}))
                out.append(await command(s, url, {"command": "ack_alert", "id": "nope"}))
                out.append(await command(s, url, {"command": "home"}))
                out.append(await command(s, url, {"command": "home"}))
                await run.sim.wait_for(is_("tour", state="aborted"), 60)
            run.executive.stop("test over")
            return out

    answers = asyncio.run(main())
    assert [(status, body["ok"]) for status, body in answers] == [
        (409, False),
        (409, False),
        (200, True),
        (409, False),
        (200, True),
        (200, True),
        (200, True),
        (200, True),
        (409, False),
        (200, True),
        (409, False),
    ]
    texts = [body.get("did") or body.get("reason") for _, body in answers]
    assert texts[0] == "not at a stop or driving to one: nothing to skip"
    # the stop as staff know it, in the site's language (config/site.yaml: es)
    assert texts[5] == "skipping Muralla almohade: on to the next stop"
    assert texts[8] == "no alert 'nope' to acknowledge"
    assert texts[9] == "ending the tour: the robot goes home and docks"


def test_auth_bad_input_size_and_rate_are_refused_with_one_line_and_change_nothing() -> None:
    async def main() -> list[tuple[int, str]]:
        async with console_tour() as (run, people, url):
            assert people.console is not None
            # two commands a second (a burst at once), and time stands still
            people.console.app[ACCESS].rates = Rates(2.0, clock=lambda: 0.0)
            await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
            out = []
            async with aiohttp.ClientSession() as s:

                async def post(data: bytes, headers: dict[str, str]) -> tuple[int, str]:
                    async with s.post(f"{url}/api/command", data=data, headers=headers) as r:
                        body = await r.json()
                        assert body["ok"] is False and "\n" not in body["reason"]
                        return r.status, body["reason"]

                home = json.dumps({"command": "home"}).encode()
                out.append(await post(home, {}))
                out.append(await post(home, auth("wrong-token-000")))
                out.append(await post(home, {"Authorization": TOKEN}))  # no scheme
                out.append(await post(b"{not json", auth()))
                out.append(await post(b'["home"]', auth()))
                out.append(await post(b'{"command": "dance"}', auth()))
                out.append(await post(b'{"command": "ack_alert"}', auth()))
                out.append(
                    await post(b'{"command": "home", "pad": "' + b"x" * 5000 + b'"}', auth())
                )
                statuses = [
                    (await command(s, url, {"command": c}))[0]
                    for c in ("pause", "resume") * (COMMAND_BURST // 2 + 1)
                ]
            assert run.executive.core.board.get(keys.HOME) is None  # nobody sent it home
            out.append((statuses.count(429), str(statuses)))
            return out

    out = asyncio.run(main())
    assert [status for status, _ in out[:8]] == [401, 401, 401, 400, 400, 400, 400, 413]
    assert out[0][1] == "a valid token is needed (Authorization: Bearer TOKEN)"
    assert out[5][1].startswith("unknown command 'dance' (known: home, skip, pause")
    assert out[7][1] == "request body over 4096 bytes"
    # a burst at once (an even number: pause, resume, ...), then two a second, no time passed
    assert out[8] == (2, str([200] * COMMAND_BURST + [429] * 2))


def test_without_a_token_file_commands_are_off_and_off_loopback_it_does_not_start(
    tmp_path: Path,
) -> None:
    async def main() -> tuple[int, str]:
        async with console_tour(token=None) as (run, _people, url):
            await run.sim.wait_for(is_("tour", state="started"), 60)
            async with aiohttp.ClientSession() as s:
                status, body = await command(s, url, {"command": "home"}, headers={})
            run.executive.stop("test over")
            return status, body["reason"]

    assert asyncio.run(main()) == (
        401,
        "commands are off: the console was started without a token file",
    )

    class Args:
        console = "0.0.0.0:8080"
        console_token_file = None

    with pytest.raises(
        UsageError,
        match=re.escape(
            "0.0.0.0 is not loopback: anyone on the network could steer the robot; give "
            "--console-token-file"
        ),
    ):
        console_settings(Args())  # type: ignore[arg-type]
    short = tmp_path / "token"
    short.write_text("abc\n")
    Args.console_token_file = short  # type: ignore[assignment]
    with pytest.raises(UsageError, match="16 to 512 characters"):
        console_settings(Args())  # type: ignore[arg-type]
    short.write_text("a-long-enough-token\n")
    settings = console_settings(Args())  # type: ignore[arg-type]
    assert settings is not None and settings.token == "a-long-enough-token"
