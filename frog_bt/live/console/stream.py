"""The pushed state: ``GET /api/stream``, a WebSocket per open page.

The state is serialised once per push and offered to every page; each page has its own
writer, which sends only the latest state it was offered, so a page that stops reading
(a phone gone to sleep, a stuck client) holds up nobody else and is dropped once a send
takes longer than ``send_timeout``. At most :data:`MAX_PAGES` pages at once (503 beyond),
and no per-message compression: the same text goes to every page, and deflating it per
client would cost the event loop (and memory) per page.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field

from aiohttp import WSCloseCode, WSMsgType, web

MAX_PAGES = 64  # open pages at once; more get 503
SEND_TIMEOUT = 2.0  # seconds one state may take to reach one page; then it is dropped
CLOSE_TIMEOUT = 1.0  # seconds the pages get when the console stops


@dataclass(eq=False)
class Page:
    """One open page: the latest state not yet sent to it."""

    ws: web.WebSocketResponse
    abort: Callable[[], None]
    latest: str | None = None
    ready: asyncio.Event = field(default_factory=asyncio.Event)

    def offer(self, text: str) -> None:
        self.latest = text
        self.ready.set()


@dataclass
class Pages:
    """The open pages, and the nudge that pushes the state to them at once."""

    push_every: float
    open: set[Page] = field(default_factory=set)
    changed: asyncio.Event = field(default_factory=asyncio.Event)
    max_pages: int = MAX_PAGES
    send_timeout: float = SEND_TIMEOUT
    dropped: int = 0

    @property
    def sockets(self) -> list[web.WebSocketResponse]:
        return [page.ws for page in self.open]

    def offer(self, text: str) -> None:
        for page in self.open:
            page.offer(text)


async def write(pages: Pages, page: Page) -> None:
    """Send ``page`` each state offered to it (the latest only), until it goes; a send
    over ``send_timeout`` drops it (its connection is aborted, not closed politely: a
    stuck client would not read a close frame either)."""
    while True:
        await page.ready.wait()
        page.ready.clear()
        text, page.latest = page.latest, None
        if text is None:
            continue
        try:
            async with asyncio.timeout(pages.send_timeout):
                await page.ws.send_str(text)
        except (TimeoutError, ConnectionError, RuntimeError):
            pages.open.discard(page)
            pages.dropped += 1
            page.abort()
            return


async def serve(request: web.Request, pages: Pages, first: str) -> web.StreamResponse:
    """One page's stream: ``first`` at once, then what :meth:`Pages.offer` gives it."""
    if len(pages.open) >= pages.max_pages:
        return web.json_response(
            {"ok": False, "reason": f"too many open pages (at most {pages.max_pages})"},
            status=503,
        )
    ws = web.WebSocketResponse(heartbeat=30.0, compress=False, max_msg_size=4096)
    await ws.prepare(request)
    transport = request.transport

    def abort() -> None:
        if transport is not None:
            transport.abort()

    page = Page(ws, abort)
    pages.open.add(page)
    page.offer(first)
    writer = asyncio.get_running_loop().create_task(write(pages, page), name="console-page")
    try:
        async for message in ws:  # the page sends nothing; this waits for it to go
            if message.type == WSMsgType.ERROR:
                break
    finally:
        pages.open.discard(page)
        writer.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await writer
    return ws


async def close_all(pages: Pages) -> None:
    """Every open page told the console is going, all within :data:`CLOSE_TIMEOUT`."""
    open_, pages.open = list(pages.open), set()
    if not open_:
        return
    with contextlib.suppress(TimeoutError):
        async with asyncio.timeout(CLOSE_TIMEOUT):
            await asyncio.gather(
                *(
                    page.ws.close(code=WSCloseCode.GOING_AWAY, message=b"the console is stopping")
                    for page in open_
                ),
                return_exceptions=True,
            )
