"""Webhook receivers on 127.0.0.1 for the alert tests: they record what they get and
answer as told; waiting for them uses their own event, never a sleep."""

from __future__ import annotations

import asyncio
import json
import socket
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from aiohttp import web

Answer = Callable[[web.Request], web.StreamResponse]


@dataclass
class Got:
    path: str
    headers: dict[str, str]
    body: Any


@dataclass
class Receiver:
    """POSTs to any path are recorded in :attr:`got` (after ``fail_first`` answers of
    ``fail_status``); ``answer`` makes the reply."""

    fail_first: int = 0
    fail_status: int = 503
    answer: Answer = field(default=lambda _r: web.Response(status=204))
    got: list[Got] = field(default_factory=list)
    calls: int = 0
    url: str = ""
    _runner: web.AppRunner | None = None
    _changed: asyncio.Condition = field(default_factory=asyncio.Condition)

    async def __aenter__(self) -> Receiver:
        app = web.Application()
        app.router.add_route("*", "/{tail:.*}", self._hook)
        self._runner = web.AppRunner(app, access_log=None)
        await self._runner.setup()
        await web.TCPSite(self._runner, "127.0.0.1", 0).start()
        self.url = f"http://127.0.0.1:{self._runner.addresses[0][1]}"
        return self

    async def __aexit__(self, *_exc: object) -> None:
        assert self._runner is not None
        await self._runner.cleanup()

    async def _hook(self, request: web.Request) -> web.StreamResponse:
        self.calls += 1
        async with self._changed:
            self._changed.notify_all()
        if self.calls <= self.fail_first:
            return web.Response(status=self.fail_status)
        raw = await request.read()
        self.got.append(Got(request.path_qs, dict(request.headers), json.loads(raw)))
        async with self._changed:
            self._changed.notify_all()
        return self.answer(request)

    async def wait_for(self, n: int, within: float = 10.0) -> list[Got]:
        """At least ``n`` bodies received (TimeoutError after ``within`` wall seconds)."""
        async with asyncio.timeout(within), self._changed:
            await self._changed.wait_for(lambda: len(self.got) >= n)
        return self.got

    async def wait_calls(self, n: int, within: float = 10.0) -> None:
        async with asyncio.timeout(within), self._changed:
            await self._changed.wait_for(lambda: self.calls >= n)


def closed_port() -> int:
    """A loopback port nobody listens on (bound, then closed)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])
