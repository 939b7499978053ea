"""A simulated tour with its console on 127.0.0.1 (a free port), for the console's tests."""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

import aiohttp
from tour import Running

from frog_bt.commands.console_options import ConsoleSettings, People, start_people

TOKEN = "staff-token-0123"


@asynccontextmanager
async def console_tour(
    scenario: dict[str, Any] | None = None,
    *,
    token: str | None = TOKEN,
    once: bool = True,
    token_file: Path | None = None,
    **kwargs: Any,
) -> AsyncIterator[tuple[Running, People, str]]:
    """The rehearsal, what was started for the people around it, and the console's URL
    (``token_file``: where the token came from; paired devices are kept beside it)."""
    # the robot's own speed (not the fast tours' 2.4 m/s): a page is read at wall pace,
    # and a stop must stay on screen long enough for a browser to see it
    scenario = {"navigation": {"speed": 0.6}, **(scenario or {})}
    async with Running(scenario, once=once, **kwargs) as run:
        settings = ConsoleSettings("127.0.0.1", 0, token, token_file)
        people = await start_people(run.executive, settings, [])
        try:
            assert people.console is not None
            yield run, people, f"http://127.0.0.1:{people.console.bound_port}"
        finally:
            await people.close()


def auth(token: str = TOKEN) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


async def command(
    session: aiohttp.ClientSession, url: str, body: Any, headers: dict[str, str] | None = None
) -> tuple[int, dict[str, Any]]:
    async with session.post(
        f"{url}/api/command?lang=en", json=body, headers=auth() if headers is None else headers
    ) as r:
        return r.status, await r.json()
