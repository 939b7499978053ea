"""The console's application lives and ends with it: the bound port found through the
runner, an open page told the console is going, the log handler gone, all within a bound."""

from __future__ import annotations

import asyncio
import logging

import aiohttp
from console_tour import console_tour
from test_faults import is_

from frog_bt.live.console.server import CLOSE_TIMEOUT, PAGES, ROUTES, SHOWN


def test_the_routes_are_the_contracts_and_declared_once() -> None:
    assert sorted((r.method, r.path) for r in ROUTES) == [  # type: ignore[attr-defined]
        ("GET", "/"),
        ("GET", "/ack/{alert_id}"),
        ("GET", "/api/devices"),
        ("GET", "/api/site"),
        ("GET", "/api/state"),
        ("GET", "/api/stream"),
        ("GET", "/api/tree"),
        ("GET", "/api/words"),
        ("GET", "/console.js"),
        ("GET", "/favicon.ico"),
        ("GET", "/pair"),
        ("GET", "/pair.js"),
        ("POST", "/ack/{alert_id}"),
        ("POST", "/api/command"),
        ("POST", "/api/handover"),
        ("POST", "/api/pair"),
        ("POST", "/api/pair/claim"),
        ("POST", "/api/ticket"),
        ("POST", "/api/unpair"),
    ]


async def _closing(ws: aiohttp.ClientWebSocketResponse) -> aiohttp.WSMessage:
    """The close the page receives, past any state pushed before it (bounded by the
    caller's timeout and the server's close)."""
    while True:
        message = await ws.receive()
        if message.type not in (aiohttp.WSMsgType.TEXT, aiohttp.WSMsgType.BINARY):
            return message


def test_closing_with_a_page_open_closes_the_page_and_drops_the_log_handler() -> None:
    async def main() -> tuple[int | None, str, bool, bool, int]:
        async with console_tour(once=False) as (run, people, url):
            console = people.console
            assert console is not None and console.bound_port is not None
            assert url.endswith(f":{console.bound_port}") and console.bound_port != 0
            await run.sim.wait_for(is_("tour", state="started"), 60)
            frog_bt = logging.getLogger("frog_bt")
            async with aiohttp.ClientSession() as s, s.ws_connect(f"{url}/api/stream") as ws:
                first = await ws.receive_json()
                assert "phase" in first
                assert console.app[PAGES].sockets  # counted before its first state
                handler_was_on = console.app[SHOWN].logs in frog_bt.handlers
                reading = asyncio.create_task(_closing(ws))  # the page answers the close
                # the pages' bound, the open requests' bound, then the pusher's bound
                async with asyncio.timeout(3 * CLOSE_TIMEOUT):
                    await console.close()
                closing = await reading
                await console.close()  # a second close does nothing
                run.executive.stop("test over")
                return (
                    ws.close_code,
                    str(closing.extra),
                    handler_was_on,
                    console.app[SHOWN].logs in frog_bt.handlers,
                    len(console.app[PAGES].sockets),
                )

    code, reason, handler_was_on, handler_is_on, pages = asyncio.run(main())
    assert (code, reason) == (1001, "the console is stopping")
    assert handler_was_on and not handler_is_on and pages == 0
