"""The operator's console over HTTP (CONTRACT §7), in the executive's own event loop.

aiohttp serves (``web.AppRunner`` + ``TCPSite``):

* ``GET /`` — the page (one file, no build step, nothing fetched from elsewhere);
* ``GET /api/state`` — the state (:func:`frog_bt.live.console.state.state`);
* ``GET /api/site`` — the static map; ``GET /api/tree`` — the whole tree, with statuses;
* ``GET /api/stream`` — a WebSocket pushing the state at most every ``console.push_every``
  seconds, and within 50 ms of a new phase or a command;
* ``POST /api/command`` — ``{"command": C}`` (``"id"`` with ``ack_alert``), with
  ``Authorization: Bearer TOKEN``: 200 ``{"ok": true, "did"}`` once applied at the next
  tick, 409 ``{"ok": false, "reason"}`` when the tour cannot do it now, 400 malformed or
  unknown, 401 no or wrong token, 413 too large, 429 too many commands a second.

Every refusal is one line of JSON ``{"ok": false, "reason": ...}`` and changes nothing.
The token is compared in constant time and never logged or recorded. Reads need no token
while the console listens on loopback; elsewhere they need it too (and the console does
not start on such an address without a token file).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import logging
import time
from collections.abc import Awaitable, Callable
from importlib import resources
from typing import TYPE_CHECKING, Any

from aiohttp import WSMsgType, web

from frog_bt.engine.operator import Command
from frog_bt.live.console.day import Day
from frog_bt.live.console.state import LogLines, StopClock, site_map, state, tree
from frog_bt.runtime.status import phase

if TYPE_CHECKING:
    from frog_bt.runtime.executive import Executive

log = logging.getLogger(__name__)
Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
SEND_TIMEOUT = 2.0  # seconds a pushed state may take to reach one page; then it is dropped
PHASE_POLL = 0.05  # wall seconds between looks at the phase (a new one is pushed at once)
CLOSE_TIMEOUT = 1.0  # seconds the server waits for open requests when it stops


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def refuse(status: int, reason: str) -> web.Response:
    return web.json_response({"ok": False, "reason": reason}, status=status)


class RateLimit:
    """At most ``rate`` commands a second (a token bucket of one second's worth)."""

    def __init__(self, rate: float, clock: Callable[[], float] = time.monotonic) -> None:
        self.rate = rate
        self.clock = clock
        self.tokens = rate
        self.at = clock()

    def take(self) -> bool:
        now = self.clock()
        self.tokens = min(self.rate, self.tokens + (now - self.at) * self.rate)
        self.at = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False


class Console:
    """One executive's console; :meth:`start` inside its loop, :meth:`close` on the way out."""

    def __init__(self, executive: Executive, host: str, port: int,
                 token: str | None = None) -> None:
        self.executive = executive
        self.host, self.port = host, port
        self.token = token
        self.loopback = is_loopback(host)
        cfg = executive.site.console
        self.max_body = cfg.max_body
        self.push_every = cfg.push_every
        self.limit = RateLimit(cfg.commands_per_second)
        self.day = Day()
        self.logs = LogLines()
        self.stop_clock = StopClock()
        self._runner: web.AppRunner | None = None
        self._sockets: set[web.WebSocketResponse] = set()
        self._changed = asyncio.Event()
        self._phase = ""
        self._pusher: asyncio.Task[None] | None = None
        self.bound_port: int | None = None

    # ------------------------------------------------------------ lifecycle

    def attach(self) -> None:
        """The day's tally and the phase watch on the executive's taps; the log lines."""
        self.day.attach(self.executive)
        logging.getLogger("frog_bt").addHandler(self.logs)

    async def start(self) -> None:
        app = web.Application(middlewares=[self._guard], client_max_size=self.max_body)
        app.router.add_get("/", self._page)
        app.router.add_get("/api/state", self._state)
        app.router.add_get("/api/site", self._site)
        app.router.add_get("/api/tree", self._tree)
        app.router.add_get("/api/stream", self._stream)
        app.router.add_post("/api/command", self._command)
        self._runner = web.AppRunner(app, access_log=None, handle_signals=False)
        await self._runner.setup()
        site = web.TCPSite(self._runner, self.host, self.port,
                           shutdown_timeout=CLOSE_TIMEOUT)  # bounded, with pages still open
        await site.start()
        server = site._server  # the bound port, when 0 was asked for
        sockets = getattr(server, "sockets", None) or ()
        self.bound_port = sockets[0].getsockname()[1] if sockets else self.port
        self._pusher = asyncio.get_running_loop().create_task(self._push())
        log.warning("console at http://%s:%d/", self.host, self.bound_port)

    async def close(self) -> None:
        logging.getLogger("frog_bt").removeHandler(self.logs)
        if self._pusher is not None:
            self._pusher.cancel()
            with contextlib.suppress(asyncio.CancelledError, TimeoutError):
                async with asyncio.timeout(CLOSE_TIMEOUT):  # bounded, come what may
                    await self._pusher
        for ws in list(self._sockets):
            with contextlib.suppress(Exception):
                await asyncio.wait_for(ws.close(), CLOSE_TIMEOUT)
        if self._runner is not None:
            await self._runner.cleanup()

    # ------------------------------------------------------------ guard

    def _authorised(self, request: web.Request) -> bool:
        """The bearer token, compared in constant time (a page's reads, whose WebSocket
        cannot send a header, may give it as ``?token=`` instead)."""
        if self.token is None:
            return False
        scheme, _, value = request.headers.get("Authorization", "").partition(" ")
        if scheme.lower() != "bearer" and request.method == "GET":
            value = request.query.get("token", "")
        return hmac.compare_digest(value.strip().encode(), self.token.encode())

    @web.middleware
    async def _guard(self, request: web.Request, handler: Handler) -> web.StreamResponse:
        """Auth, size and refusals as one line of JSON, in one place."""
        needs_token = request.method != "GET" or not self.loopback
        if needs_token and request.path.startswith("/api") and not self._authorised(request):
            return refuse(401, "a valid token is needed (Authorization: Bearer TOKEN)"
                          if self.token is not None else
                          "commands are off: the console was started without a token file")
        if request.content_length is not None and request.content_length > self.max_body:
            return refuse(413, f"request body over {self.max_body} bytes")
        try:
            return await handler(request)
        except web.HTTPRequestEntityTooLarge:
            return refuse(413, f"request body over {self.max_body} bytes")
        except web.HTTPException as exc:
            if exc.status >= 400:
                return refuse(exc.status, exc.reason)
            raise

    # ------------------------------------------------------------ reads

    def snapshot(self) -> dict[str, Any]:
        return state(self.executive, self.day, self.logs, self.stop_clock)

    async def _page(self, _request: web.Request) -> web.Response:
        page = resources.files("frog_bt.live.console").joinpath("page.html").read_text("utf-8")
        return web.Response(text=page, content_type="text/html")

    async def _state(self, _request: web.Request) -> web.Response:
        return web.json_response(self.snapshot())

    async def _site(self, _request: web.Request) -> web.Response:
        return web.json_response(site_map(self.executive))

    async def _tree(self, _request: web.Request) -> web.Response:
        return web.json_response(tree(self.executive.core.root))

    # ------------------------------------------------------------ pushed state

    async def _stream(self, request: web.Request) -> web.WebSocketResponse:
        ws = web.WebSocketResponse(heartbeat=30.0)
        await ws.prepare(request)
        self._sockets.add(ws)
        try:
            await ws.send_str(json.dumps(self.snapshot()))
            async for message in ws:  # the page sends nothing; this waits for it to go
                if message.type == WSMsgType.ERROR:
                    break
        finally:
            self._sockets.discard(ws)
        return ws

    async def _push(self) -> None:
        """The state to every page every ``push_every`` seconds, and within
        :data:`PHASE_POLL` of a new phase or a command; a page that does not take it within
        :data:`SEND_TIMEOUT` is dropped. The phase is looked at here, between ticks, not
        after each tick: the console costs the tick nothing."""
        loop = asyncio.get_running_loop()
        last, last_at = "", 0.0
        while True:
            # asyncio.timeout, not wait_for: on Python 3.11 wait_for can swallow a cancel
            # that meets the event being set, and close() would then wait for ever
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(PHASE_POLL):
                    await self._changed.wait()
            now_phase = phase(self.executive.core)
            due = (self._changed.is_set() or now_phase != self._phase
                   or loop.time() - last_at >= self.push_every)
            self._changed.clear()
            self._phase = now_phase
            if not due or not self._sockets:
                continue
            last_at = loop.time()
            text = json.dumps(self.snapshot())
            if text == last:
                continue
            last = text
            for ws in list(self._sockets):
                try:
                    async with asyncio.timeout(SEND_TIMEOUT):
                        await ws.send_str(text)
                except (TimeoutError, ConnectionError, RuntimeError):
                    self._sockets.discard(ws)
                    with contextlib.suppress(Exception):
                        await ws.close()

    # ------------------------------------------------------------ commands

    async def _command(self, request: web.Request) -> web.Response:
        try:
            body = await request.json()
        except (ValueError, UnicodeDecodeError):
            return refuse(400, "the body is not JSON: send {\"command\": ...}")
        if not isinstance(body, dict) or not isinstance(body.get("command"), str):
            return refuse(400, "expected a JSON object with \"command\"")
        try:
            command = Command(body["command"])
        except ValueError:
            known = ", ".join(c.value for c in Command)
            return refuse(400, f"unknown command {body['command'][:40]!r} (known: {known})")
        alert_id = body.get("id", "")
        if command is Command.ACK_ALERT and (not isinstance(alert_id, str) or not alert_id):
            return refuse(400, "ack_alert needs the alert's \"id\"")
        if not self.limit.take():
            return refuse(429, "too many commands: wait a second")
        answer = await self.executive.staff.submit(command, alert_id if isinstance(
            alert_id, str) else "")
        self._changed.set()
        if not answer.ok:
            return refuse(409, answer.text)
        return web.json_response({"ok": True, "did": answer.text})
