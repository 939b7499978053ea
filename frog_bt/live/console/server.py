"""The operator's console over HTTP (CONTRACT §7), in the executive's own event loop.

:func:`make_app` builds the aiohttp application, :class:`Console` runs it
(``web.AppRunner`` + ``TCPSite``). The routes, all in :data:`ROUTES`:

* ``GET /`` — the page (one file, no build step, nothing fetched from elsewhere);
* ``GET /api/state`` — the state (:func:`frog_bt.live.console.state.state`);
* ``GET /api/site`` — the static map; ``GET /api/tree`` — the whole tree, with statuses;
* ``GET /api/stream`` — a WebSocket pushing the state at most every ``console.push_every``
  seconds, and within 50 ms of a new phase or a command;
* ``GET /ack/{alert_id}?exp=&sig=`` — a notification's signed link acknowledges its alert
  (:func:`get_ack`), answering a plain page;
* ``POST /api/command`` — ``{"command": C}`` (``"id"`` with ``ack_alert``), with
  ``Authorization: Bearer TOKEN``: 200 ``{"ok": true, "did"}`` once applied at the next
  tick, 409 ``{"ok": false, "reason"}`` when the tour cannot do it now, 400 malformed or
  unknown, 401 no or wrong token, 413 too large, 429 too many commands a second.

Every refusal is one line of JSON ``{"ok": false, "reason": ...}`` and changes nothing.
The token is compared in constant time and never logged or recorded. Reads need no token
while the console listens on loopback; elsewhere they need it too (and the console does
not start on such an address without a token file).

What one console keeps lives in its application, under typed keys: :data:`EXECUTIVE`,
:data:`ACCESS` (who may do what), :data:`SHOWN` (the day, the log lines, the stop clock)
and :data:`PAGES` (the open WebSockets). Its lifetime is the application's: the log
handler and the pusher start with it and end with it (``cleanup_ctx``), the pages are
closed, within :data:`CLOSE_TIMEOUT`, as it shuts down (``on_shutdown``).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import html
import ipaddress
import json
import logging
import time
from collections.abc import AsyncIterator, Awaitable, Callable
from dataclasses import dataclass, field
from importlib import resources
from typing import TYPE_CHECKING, Any

from aiohttp import WSCloseCode, WSMsgType, web

from frog_bt.engine.operator import Command
from frog_bt.live.console.acklink import Verdict, link_key, verify
from frog_bt.live.console.day import Day
from frog_bt.live.console.state import LogLines, StopClock, site_map, state, tree
from frog_bt.runtime.status import phase

if TYPE_CHECKING:
    from frog_bt.runtime.executive import Executive

log = logging.getLogger(__name__)
Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
SEND_TIMEOUT = 2.0  # seconds a pushed state may take to reach one page; then it is dropped
PHASE_POLL = 0.05  # wall seconds between looks at the phase (a new one is pushed at once)
CLOSE_TIMEOUT = 1.0  # seconds the pages, then the open requests, get when the console stops


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


# ---------------------------------------------------------------- one console's state


@dataclass
class Access:
    """Who may do what: the staff token (None: commands are off), whether reads are open
    (on loopback), the largest body and the command rate."""

    token: str | None
    loopback: bool
    max_body: int
    limit: RateLimit


@dataclass
class Shown:
    """What the page shows beside the executive's own state."""

    day: Day
    logs: LogLines
    stop_clock: StopClock


@dataclass
class Pages:
    """The open pages, and the nudge that pushes the state to them at once."""

    push_every: float
    sockets: set[web.WebSocketResponse] = field(default_factory=set)
    changed: asyncio.Event = field(default_factory=asyncio.Event)


EXECUTIVE: web.AppKey[Executive] = web.AppKey("executive")
ACCESS = web.AppKey("access", Access)
SHOWN = web.AppKey("shown", Shown)
PAGES = web.AppKey("pages", Pages)


def snapshot(app: web.Application) -> dict[str, Any]:
    shown = app[SHOWN]
    return state(app[EXECUTIVE], shown.day, shown.logs, shown.stop_clock)


# ---------------------------------------------------------------- guard


def authorised(access: Access, request: web.Request) -> bool:
    """The bearer token, compared in constant time (a page's reads, whose WebSocket
    cannot send a header, may give it as ``?token=`` instead)."""
    if access.token is None:
        return False
    scheme, _, value = request.headers.get("Authorization", "").partition(" ")
    if scheme.lower() != "bearer" and request.method == "GET":
        value = request.query.get("token", "")
    return hmac.compare_digest(value.strip().encode(), access.token.encode())


@web.middleware
async def guard(request: web.Request, handler: Handler) -> web.StreamResponse:
    """Auth, size and refusals as one line of JSON, in one place."""
    access = request.app[ACCESS]
    needs_token = request.method != "GET" or not access.loopback
    if needs_token and request.path.startswith("/api") and not authorised(access, request):
        return refuse(
            401,
            "a valid token is needed (Authorization: Bearer TOKEN)"
            if access.token is not None
            else "commands are off: the console was started without a token file",
        )
    if request.content_length is not None and request.content_length > access.max_body:
        return refuse(413, f"request body over {access.max_body} bytes")
    try:
        return await handler(request)
    except web.HTTPRequestEntityTooLarge:
        return refuse(413, f"request body over {access.max_body} bytes")
    except web.HTTPException as exc:
        if exc.status >= 400:
            return refuse(exc.status, exc.reason)
        raise


# ---------------------------------------------------------------- reads


async def get_page(_request: web.Request) -> web.Response:
    page = resources.files("frog_bt.live.console").joinpath("page.html").read_text("utf-8")
    return web.Response(text=page, content_type="text/html")


async def get_state(request: web.Request) -> web.Response:
    return web.json_response(snapshot(request.app))


async def get_site(request: web.Request) -> web.Response:
    return web.json_response(site_map(request.app[EXECUTIVE]))


async def get_tree(request: web.Request) -> web.Response:
    return web.json_response(tree(request.app[EXECUTIVE].core.root))


# ---------------------------------------------------------------- pushed state


async def get_stream(request: web.Request) -> web.WebSocketResponse:
    pages = request.app[PAGES]
    ws = web.WebSocketResponse(heartbeat=30.0)
    await ws.prepare(request)
    pages.sockets.add(ws)
    try:
        await ws.send_str(json.dumps(snapshot(request.app)))
        async for message in ws:  # the page sends nothing; this waits for it to go
            if message.type == WSMsgType.ERROR:
                break
    finally:
        pages.sockets.discard(ws)
    return ws


async def push(app: web.Application) -> None:
    """The state to every page every ``push_every`` seconds, and within
    :data:`PHASE_POLL` of a new phase or a command; a page that does not take it within
    :data:`SEND_TIMEOUT` is dropped. The phase is looked at here, between ticks, not
    after each tick: the console costs the tick nothing."""
    loop = asyncio.get_running_loop()
    pages, core = app[PAGES], app[EXECUTIVE].core
    last, last_at, last_phase = "", 0.0, ""
    while True:
        # asyncio.timeout, not wait_for: on Python 3.11 wait_for can swallow a cancel
        # that meets the event being set, and the cleanup would then wait for ever
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(PHASE_POLL):
                await pages.changed.wait()
        now_phase = phase(core)
        due = (
            pages.changed.is_set()
            or now_phase != last_phase
            or loop.time() - last_at >= pages.push_every
        )
        pages.changed.clear()
        last_phase = now_phase
        if not due or not pages.sockets:
            continue
        last_at = loop.time()
        text = json.dumps(snapshot(app))
        if text == last:
            continue
        last = text
        for ws in list(pages.sockets):
            try:
                async with asyncio.timeout(SEND_TIMEOUT):
                    await ws.send_str(text)
            except (TimeoutError, ConnectionError, RuntimeError):
                pages.sockets.discard(ws)
                with contextlib.suppress(Exception):
                    await ws.close()


# ---------------------------------------------------------------- commands


async def post_command(request: web.Request) -> web.Response:
    try:
        body = await request.json()
    except (ValueError, UnicodeDecodeError):
        return refuse(400, 'the body is not JSON: send {"command": ...}')
    if not isinstance(body, dict) or not isinstance(body.get("command"), str):
        return refuse(400, 'expected a JSON object with "command"')
    try:
        command = Command(body["command"])
    except ValueError:
        known = ", ".join(c.value for c in Command)
        return refuse(400, f"unknown command {body['command'][:40]!r} (known: {known})")
    alert_id = body.get("id", "")
    if command is Command.ACK_ALERT and (not isinstance(alert_id, str) or not alert_id):
        return refuse(400, 'ack_alert needs the alert\'s "id"')
    if not request.app[ACCESS].limit.take():
        return refuse(429, "too many commands: wait a second")
    answer = await request.app[EXECUTIVE].staff.submit(
        command, alert_id if isinstance(alert_id, str) else ""
    )
    request.app[PAGES].changed.set()
    if not answer.ok:
        return refuse(409, answer.text)
    return web.json_response({"ok": True, "did": answer.text})


# ---------------------------------------------------------------- acknowledgement links


def plain_page(status: int, title: str, text: str) -> web.Response:
    """A small page of text: no script, no style, nothing fetched, never cached."""
    body = (
        '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width">'
        f"<title>{html.escape(title)}</title></head>\n<body><h1>{html.escape(title)}</h1>"
        f"\n<p>{html.escape(text)}</p></body></html>\n"
    )
    return web.Response(
        status=status,
        text=body,
        content_type="text/html",
        headers={
            "Content-Security-Policy": "default-src 'none'; frame-ancestors 'none'",
            "X-Content-Type-Options": "nosniff",
            "Cache-Control": "no-store",
            "Referrer-Policy": "no-referrer",
        },
    )


async def get_ack(request: web.Request) -> web.Response:
    """``GET /ack/{alert_id}?exp=&sig=``: a signed link from a notification
    (:mod:`~frog_bt.live.console.acklink`) acknowledges exactly its alert, through the
    staff queue like ``ack_alert``. An expired, tampered or other alert's link: 403, and
    nothing is acknowledged. Expiry is on the wall clock (the phone is)."""
    access = request.app[ACCESS]
    alert_id = request.match_info["alert_id"]
    verdict = (
        verify(
            link_key(access.token),
            alert_id,
            request.query.get("exp", ""),
            request.query.get("sig", ""),
            time.time(),
        )
        if access.token is not None
        else Verdict.BAD
    )
    if verdict is Verdict.EXPIRED:
        return plain_page(
            403,
            "Link expired",
            "This link has expired: nothing was acknowledged. Open the console to see the alerts.",
        )
    if verdict is not Verdict.VALID:
        return plain_page(
            403, "Not a valid link", "This link is not valid: nothing was acknowledged."
        )
    if not access.limit.take():
        return plain_page(429, "Too many requests", "Wait a second, then open the link again.")
    answer = await request.app[EXECUTIVE].staff.submit(Command.ACK_ALERT, alert_id)
    request.app[PAGES].changed.set()
    if not answer.ok:
        return plain_page(409, "Nothing acknowledged", f"Not done: {answer.text}.")
    return plain_page(200, "Acknowledged", f"Done: {answer.text}. Thank you.")


ROUTES = [
    web.get("/", get_page),
    web.get("/api/state", get_state),
    web.get("/api/site", get_site),
    web.get("/api/tree", get_tree),
    web.get("/api/stream", get_stream),
    web.post("/api/command", post_command),
    web.get("/ack/{alert_id}", get_ack, allow_head=False),  # HEAD acknowledges nothing
]


# ---------------------------------------------------------------- lifetime


async def log_lines(app: web.Application) -> AsyncIterator[None]:
    """The console's log handler on ``frog_bt`` while the application runs (it keeps only
    its executive's lines: :class:`~frog_bt.live.console.state.LogLines`)."""
    logger = logging.getLogger("frog_bt")
    logger.addHandler(app[SHOWN].logs)
    try:
        yield
    finally:
        logger.removeHandler(app[SHOWN].logs)


async def pusher(app: web.Application) -> AsyncIterator[None]:
    """:func:`push` while the application runs; cancelled, within a bound, as it ends."""
    task = asyncio.get_running_loop().create_task(push(app), name="console-push")
    try:
        yield
    finally:
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError, TimeoutError):
            async with asyncio.timeout(CLOSE_TIMEOUT):  # bounded, come what may
                await task


async def close_pages(app: web.Application) -> None:
    """Every open page told the console is going, all within :data:`CLOSE_TIMEOUT`."""
    pages = app[PAGES]
    sockets, pages.sockets = list(pages.sockets), set()
    if not sockets:
        return
    with contextlib.suppress(TimeoutError):
        async with asyncio.timeout(CLOSE_TIMEOUT):
            await asyncio.gather(
                *(
                    ws.close(code=WSCloseCode.GOING_AWAY, message=b"the console is stopping")
                    for ws in sockets
                ),
                return_exceptions=True,
            )


def make_app(executive: Executive, *, token: str | None, loopback: bool) -> web.Application:
    """``executive``'s console as an application: its routes, its state, its lifetime.
    ``token`` (None: commands are off); ``loopback``: whether reads need no token."""
    cfg = executive.site.console
    app = web.Application(middlewares=[guard], client_max_size=cfg.max_body)
    app[EXECUTIVE] = executive
    app[ACCESS] = Access(token, loopback, cfg.max_body, RateLimit(cfg.commands_per_second))
    app[SHOWN] = Shown(Day(), LogLines(owner=executive), StopClock())
    app[PAGES] = Pages(cfg.push_every)
    app.add_routes(ROUTES)
    app.cleanup_ctx.extend([log_lines, pusher])
    app.on_shutdown.append(close_pages)
    return app


class Console:
    """One executive's console on ``host:port`` (0: any free port, then :attr:`bound_port`):
    :meth:`attach` before the executive runs, :meth:`start` inside its loop, :meth:`close`
    on the way out."""

    def __init__(
        self, executive: Executive, host: str, port: int, token: str | None = None
    ) -> None:
        self.executive = executive
        self.host, self.port = host, port
        self.app = make_app(executive, token=token, loopback=is_loopback(host))
        self.bound_port: int | None = None
        # bounded, with pages still open
        self._runner = web.AppRunner(
            self.app, access_log=None, handle_signals=False, shutdown_timeout=CLOSE_TIMEOUT
        )
        self._started = False

    def attach(self) -> None:
        """The day's tally among the executive's observers."""
        self.executive.observers.attach(self.executive, [self.app[SHOWN].day])

    async def start(self) -> None:
        """Listen; OSError when the address cannot be bound (then :meth:`close`)."""
        self._started = True
        await self._runner.setup()
        await web.TCPSite(self._runner, self.host, self.port).start()
        self.bound_port = int(self._runner.addresses[0][1])
        log.warning("console at http://%s:%d/", self.host, self.bound_port)

    async def close(self) -> None:
        """The pages closed, the open requests given :data:`CLOSE_TIMEOUT`, then the pusher
        and the log handler gone. Once; nothing to do when never started."""
        if self._started:
            self._started = False
            await self._runner.cleanup()
