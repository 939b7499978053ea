"""The operator's console over HTTP (CONTRACT §7), in the executive's own event loop.

:func:`make_app` builds the aiohttp application, :class:`Console` runs it
(``web.AppRunner`` + :class:`~frog_bt.live.console.gate.GatedSite`). The routes, all in
:data:`ROUTES`:

* ``GET /`` — the page, and ``GET /console.js`` its script (nothing fetched from
  elsewhere, nothing inline but the page's style, allowed by its hash);
* ``GET /api/state`` — the state (:func:`frog_bt.live.console.state.state`);
* ``GET /api/site`` — the static map; ``GET /api/tree`` — the whole tree, with statuses
  (both cached: serialised once per site, once per tick);
* ``GET /api/stream`` — a WebSocket pushing the state at most every ``console.push_every``
  seconds, and within 50 ms of a new phase or a command (:mod:`~.stream`);
* ``POST /api/ticket`` — with the token: a one-use ticket for ``/api/stream?ticket=``, so
  that off loopback the token never travels in a URL (:mod:`~.bearer`);
* ``GET /ack/{alert_id}?at=&exp=&sig=`` — a notification's signed link: a plain page in
  the site's language saying what it would acknowledge, with one button; ``POST`` (the
  button) acknowledges that raise of that alert, once (:mod:`~.ackpage`);
* ``POST /api/handover`` — with the token: the shift handed over now (:mod:`~.shift`):
  composed, sent to the webhooks, kept as the page's *Relevo*, and answered;
* ``POST /api/command`` — ``{"command": C}`` (``"id"`` with ``ack_alert``), with
  ``Authorization: Bearer TOKEN``: 200 ``{"ok": true, "did"}`` once applied at the next
  tick, 409 ``{"ok": false, "reason"}`` when the tour cannot do it now, 400 malformed or
  unknown, 401 no or wrong token, 413 too large, 429 too many commands a second from
  one client.

Every request passes :func:`guard` first: a ``Host`` or ``Origin`` that is not the
console's gets 403 (:mod:`~.origins`); then the token, where one is needed (only the
``Bearer`` scheme; failed attempts counted per client and in total, logged once a minute,
and over their budget answered 429 — the right token is never refused for anyone's
failures: :mod:`~.throttle`); then the body's size. Every refusal is one line of JSON
``{"ok": false, "reason": ...}`` and changes nothing; every answer carries a strict
Content-Security-Policy (:data:`SECURITY_HEADERS`; aiohttp's own errors too: :mod:`~.gate`),
the console's identity and, to ``ctl``, the proof of it. The token is compared in
constant time and never logged or recorded. Reads need no token when the console listens
on loopback and the request names a loopback host and came through no proxy; elsewhere
they need it too (and the console does not start off loopback without a token file).

What one console keeps lives in its application, under typed keys: :data:`EXECUTIVE`,
:data:`ACCESS` (who may do what), :data:`SHOWN` (the day, the log lines, the stop clock,
the cached reads) and :data:`PAGES` (the open WebSockets). Its lifetime is the
application's: the log handler and the pusher start with it and end with it
(``cleanup_ctx``), the pages are closed, within :data:`CLOSE_TIMEOUT`, as it shuts down
(``on_shutdown``).
"""

from __future__ import annotations

import asyncio
import base64
import contextlib
import hashlib
import json
import logging
import re
import socket
from collections.abc import AsyncIterator, Awaitable, Callable
from dataclasses import dataclass, field
from importlib import resources
from typing import TYPE_CHECKING, Any

from aiohttp import web

from frog_bt.engine.operator import Command
from frog_bt.i18n import LANGUAGES, Msg, catalog, language, say
from frog_bt.live.console import CTL_AGENT
from frog_bt.live.console.acklink import answer_proof, console_id, link_key
from frog_bt.live.console.ackpage import ACK_DESK, AckDesk, get_ack, post_ack
from frog_bt.live.console.bearer import Tickets, bearer, matches
from frog_bt.live.console.day import Day
from frog_bt.live.console.devices import Devices, Pairings
from frog_bt.live.console.gate import Door, GatedSite, OutOfFiles, connection_cap
from frog_bt.live.console.handover import Handover, shown
from frog_bt.live.console.origins import Origins, is_loopback, split_host
from frog_bt.live.console.pairing import CLAIM, DEVICE, PAIR_DESK, PairDesk, device_of
from frog_bt.live.console.pairing import ROUTES as PAIR_ROUTES
from frog_bt.live.console.shift import Shift
from frog_bt.live.console.state import LogLines, StopClock, site_map, state, tree
from frog_bt.live.console.stream import CLOSE_TIMEOUT, Pages, close_all, serve
from frog_bt.live.console.throttle import Failures, Network, Rates, client_of, networks
from frog_bt.runtime.status import phase

if TYPE_CHECKING:
    from frog_bt.config import Site
    from frog_bt.runtime.executive import Executive

__all__ = ["ACCESS", "CLOSE_TIMEOUT", "PAGES", "ROUTES", "SHOWN", "Console", "is_loopback"]

log = logging.getLogger(__name__)
if log.level == logging.NOTSET:  # where the console is: at INFO, always in the log
    log.setLevel(logging.INFO)
Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
PHASE_POLL = 0.05  # wall seconds between looks at the phase (a new one is pushed at once)
HEADER_TIMEOUT = 10.0  # seconds a connection may take to send a whole request header
PROXIED = ("Forwarded", "X-Forwarded-For", "X-Real-IP")  # a request that came via a proxy
MAX_NONCE = 64  # characters of X-Frog-Nonce answered with a proof


def refuse(status: int, reason: str) -> web.Response:
    return web.json_response({"ok": False, "reason": reason}, status=status)


# ---------------------------------------------------------------- one console's state


@dataclass
class Access:
    """Who may do what: the staff token (None: commands are off), whether the console
    listens on loopback, the console's own origins, the largest body, the command rate
    per client, the failed attempts, the stream tickets and the proxies whose
    ``X-Forwarded-For`` names the client."""

    token: str | None
    loopback: bool
    max_body: int
    rates: Rates
    origins: Origins
    failures: Failures = field(default_factory=Failures)
    tickets: Tickets = field(default_factory=Tickets)
    proxies: tuple[Network, ...] = ()

    def client(self, request: web.Request) -> str:
        """The client ``request`` stands for (:func:`~.throttle.client_of`)."""
        return client_of(
            request.remote, request.headers.getall("X-Forwarded-For", []), self.proxies
        )


@dataclass
class Shown:
    """What the page shows beside the executive's own state, and the reads kept between
    changes (the tree per core and tick, the map per site)."""

    day: Day
    shift: Shift
    logs: LogLines
    stop_clock: StopClock
    cached: dict[str, tuple[object, int, bytes]] = field(default_factory=dict)

    def cache(self, name: str, owner: object, version: int, make: Callable[[], Any]) -> bytes:
        """``make()`` as JSON bytes, made again only when ``owner`` or ``version`` changed."""
        held = self.cached.get(name)
        if held is not None and held[0] is owner and held[1] == version:
            return held[2]
        body = json.dumps(make()).encode()
        self.cached[name] = (owner, version, body)
        return body


@dataclass(frozen=True)
class Assets:
    """The page, its script and the policy that allows exactly them."""

    page: str
    script: str
    policy: str


EXECUTIVE: web.AppKey[Executive] = web.AppKey("executive")
ACCESS = web.AppKey("access", Access)
SHOWN = web.AppKey("shown", Shown)
PAGES = web.AppKey("pages", Pages)
ASSETS = web.AppKey("assets", Assets)


def load_assets() -> Assets:
    files = resources.files("frog_bt.live.console")
    page = files.joinpath("page.html").read_text("utf-8")
    pair_page = files.joinpath("pair.html").read_text("utf-8")
    styles = re.findall(r"<style>(.*?)</style>", page + pair_page, re.DOTALL)
    hashes = " ".join(
        f"'sha256-{base64.b64encode(hashlib.sha256(s.encode()).digest()).decode()}'" for s in styles
    )
    policy = (
        "default-src 'self'; script-src 'self'; "
        f"style-src 'self' {hashes}; img-src 'self'; connect-src 'self'; "
        "object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'; "
        "require-trusted-types-for 'script'"
    )
    return Assets(page, files.joinpath("console.js").read_text("utf-8"), policy)


SECURITY_HEADERS = {
    "X-Content-Type-Options": "nosniff",
    "X-Frame-Options": "DENY",
    "Referrer-Policy": "no-referrer",
    "Cross-Origin-Opener-Policy": "same-origin",
    "Cross-Origin-Resource-Policy": "same-origin",
}


async def secure_headers(request: web.Request, response: web.StreamResponse) -> None:
    """Every answer: the page's policy (or, for JSON and plain pages, one that allows
    nothing), no sniffing, no framing, no referrer; with a token, the console's identity
    (``X-Frog-Console``) and, when the request sent an ``X-Frog-Nonce``, the proof that this
    body is this console's answer to it (``X-Frog-Proof``: what ``ctl`` checks)."""
    response.headers.setdefault("Content-Security-Policy", request.app[ASSETS].policy)
    for name, value in SECURITY_HEADERS.items():
        response.headers.setdefault(name, value)
    if request.path.startswith("/api"):
        response.headers.setdefault("Cache-Control", "no-store")
    token = request.app[ACCESS].token
    if token is None:
        return
    response.headers["X-Frog-Console"] = console_id(token)
    nonce = request.headers.get("X-Frog-Nonce", "")
    body = response.body if isinstance(response, web.Response) else None
    if nonce and len(nonce) <= MAX_NONCE and nonce.isascii() and isinstance(body, bytes):
        response.headers["X-Frog-Proof"] = answer_proof(token, nonce, body)


def snapshot(app: web.Application) -> dict[str, Any]:
    kept = app[SHOWN]
    token = app[ACCESS].token
    return {
        **state(app[EXECUTIVE], kept.day, kept.logs, kept.stop_clock),
        "console": console_id(token) if token is not None else None,
        "handover": _handover(app, kept.shift.last),
    }


def _handover(app: web.Application, last: Handover | None) -> dict[str, Any] | None:
    """The last handover as the page shows it (the site's language), or None."""
    if last is None:
        return None
    executive = app[EXECUTIVE]
    site = executive.site
    return shown(last, site.alerts.robot, site.language, executive.clock.tz)


# ---------------------------------------------------------------- guard


def reached(request: web.Request) -> str | None:
    """The local address the connection came in on (the console's own, on 0.0.0.0)."""
    transport = request.transport
    sockname = transport.get_extra_info("sockname") if transport is not None else None
    return str(sockname[0]) if isinstance(sockname, tuple) and sockname else None


def reads_open(access: Access, request: web.Request) -> bool:
    """Reads without a token: the console is on loopback, the request names a loopback
    host and came through no proxy (behind a proxy, anyone could be asking)."""
    if not access.loopback or any(name in request.headers for name in PROXIED):
        return False
    host = split_host(request.headers.get("Host", ""))
    return host is not None and is_loopback(host[0])


def token_refusal(access: Access, request: web.Request) -> web.Response | None:
    """None when the request may go on (the right token is never refused here, whatever
    anyone's failures); else the 401, or the 429 of a failure over its budget."""
    given = bearer(request.headers.get("Authorization"))
    if matches(given, access.token):
        return None
    devices = request.app[PAIR_DESK].devices
    device = devices.find(given) if access.token is not None else None
    if device is not None:  # a paired phone: its own key, its name on what it does
        request[DEVICE] = device
        devices.seen(device)
        return None
    if request.path == "/api/stream" and access.tickets.spend(request.query.get("ticket", "")):
        return None
    if access.failures.failed(access.client(request)):
        return refuse(429, "too many failed attempts: wait a minute")
    return refuse(
        401,
        "a valid token is needed (Authorization: Bearer TOKEN)"
        if access.token is not None
        else "commands are off: the console was started without a token file",
    )


@web.middleware
async def guard(request: web.Request, handler: Handler) -> web.StreamResponse:
    """Origins, auth, size and refusals as one line of JSON, in one place."""
    access = request.app[ACCESS]
    here = reached(request)
    if not access.origins.host_ok(request.headers.get("Host"), here):
        return refuse(403, "this console does not answer to that Host")
    if not access.origins.origin_ok(request.headers.get("Origin"), here):
        return refuse(403, "a page from another origin may not use this console")
    needs_token = request.method != "GET" or not reads_open(access, request)
    if needs_token and request.path.startswith("/api") and request.path != CLAIM:
        refusal = token_refusal(access, request)
        if refusal is not None:
            return refusal
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


async def get_page(request: web.Request) -> web.Response:
    return web.Response(text=request.app[ASSETS].page, content_type="text/html")


async def get_script(request: web.Request) -> web.Response:
    return web.Response(text=request.app[ASSETS].script, content_type="text/javascript")


FAVICON = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 32 32">'
    '<rect width="32" height="32" rx="7" fill="#14532d"/>'
    '<circle cx="11" cy="12" r="4.5" fill="#fff"/><circle cx="21" cy="12" r="4.5" fill="#fff"/>'
    '<circle cx="11" cy="12" r="2" fill="#14532d"/><circle cx="21" cy="12" r="2" fill="#14532d"/>'
    '<path d="M7 21 Q16 28 25 21" stroke="#fff" stroke-width="2.5" fill="none"/></svg>'
)


async def get_favicon(request: web.Request) -> web.Response:
    return web.Response(
        text=FAVICON, content_type="image/svg+xml", headers={"Cache-Control": "max-age=86400"}
    )


async def get_words(request: web.Request) -> web.Response:
    """``GET /api/words?lang=es``: every sentence of the catalogs in that language (the
    page translates its own words and the state's with them), as JSON text."""
    lang = language(request.query.get("lang") or request.app[EXECUTIVE].site.language)
    return web.json_response({"language": lang, "languages": LANGUAGES, "words": catalog(lang)})


def by_name(words: Msg | str, site: Site) -> Msg | str:
    """An answer with its stop by the name staff know it by (``skipping Hunting
    Courtyard``, not ``skipping POI2``)."""
    if not isinstance(words, Msg):
        return words
    args = {k: site.name(v) if k == "stop" and isinstance(v, str) else v for k, v in words.args}
    return Msg(words.msgid, **args)


def public_url(console_url: str, request: web.Request) -> str:
    """The console's address as a phone reaches it: ``alerts.console_url``, else the
    address this request named (its ``Host``, already checked to be the console's)."""
    return console_url or f"{request.scheme}://{request.host}"


def asked_language(request: web.Request) -> str:
    """The language an answer is given in: ``?lang=`` (the page's), else the site's."""
    return language(request.query.get("lang") or request.app[EXECUTIVE].site.language)


async def get_state(request: web.Request) -> web.Response:
    return web.json_response(snapshot(request.app))


def _json(body: bytes) -> web.Response:
    return web.Response(body=body, content_type="application/json")


async def get_site(request: web.Request) -> web.Response:
    executive = request.app[EXECUTIVE]
    shown = request.app[SHOWN]
    return _json(shown.cache("site", executive.site, 0, lambda: site_map(executive)))


async def get_tree(request: web.Request) -> web.Response:
    core = request.app[EXECUTIVE].core
    return _json(request.app[SHOWN].cache("tree", core, core.ticks, lambda: tree(core.root)))


async def post_ticket(request: web.Request) -> web.Response:
    tickets = request.app[ACCESS].tickets
    return web.json_response({"ok": True, "ticket": tickets.issue(), "expires_in": tickets.ttl})


# ---------------------------------------------------------------- pushed state


async def get_stream(request: web.Request) -> web.StreamResponse:
    return await serve(request, request.app[PAGES], json.dumps(snapshot(request.app)))


async def push(app: web.Application) -> None:
    """The state to every page every ``push_every`` seconds, and within
    :data:`PHASE_POLL` of a new phase or a command (each page takes it at its own pace:
    :mod:`~frog_bt.live.console.stream`). The phase is looked at here, between ticks, not
    after each tick: the console costs the tick nothing."""
    loop = asyncio.get_running_loop()
    pages, executive, failures = app[PAGES], app[EXECUTIVE], app[ACCESS].failures
    shift = app[SHOWN].shift
    last, last_at, last_phase = "", 0.0, ""
    while True:
        # asyncio.timeout, not wait_for: on Python 3.11 wait_for can swallow a cancel
        # that meets the event being set, and the cleanup would then wait for ever
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(PHASE_POLL):
                await pages.changed.wait()
        failures.flush()  # the failed attempts of the last minute, once a minute
        clock = executive.core.clock
        if clock.ready and shift.check(clock.now()) is not None:  # no tick meanwhile
            pages.changed.set()
        now_phase = phase(executive.core)
        due = (
            pages.changed.is_set()
            or now_phase != last_phase
            or loop.time() - last_at >= pages.push_every
        )
        pages.changed.clear()
        last_phase = now_phase
        if not due or not pages.open:
            continue
        last_at = loop.time()
        text = json.dumps(snapshot(app))
        if text != last:
            last = text
            pages.offer(text)


# ---------------------------------------------------------------- commands


def sender(request: web.Request) -> str:
    """Who sent a command (recorded as its ``by``): a paired device by its name
    (``device:NAME``, plain text of at most 64 characters), ``ctl`` or the console."""
    device = device_of(request)
    if device is not None:
        return f"device:{device.name}"
    return "ctl" if request.headers.get("User-Agent", "").startswith(CTL_AGENT) else "console"


async def post_handover(request: web.Request) -> web.Response:
    """``POST /api/handover``: the shift handed over now, by whoever asked."""
    access = request.app[ACCESS]
    if not access.rates.take(access.client(request)):
        return refuse(429, "too many commands: wait a second")
    executive = request.app[EXECUTIVE]
    if not executive.core.clock.ready:
        return refuse(409, "the executive has no time yet: nothing to hand over")
    handover = request.app[SHOWN].shift.hand_over(executive.core.clock.now(), by=sender(request))
    request.app[PAGES].changed.set()
    return web.json_response({"ok": True, "handover": _handover(request.app, handover)})


UTF8 = (None, "utf-8", "utf8")


async def post_command(request: web.Request) -> web.Response:
    try:
        charset = request.charset
    except ValueError:
        charset = "?"
    if (charset.lower() if charset else None) not in UTF8:
        return refuse(400, "the body must be JSON in UTF-8 (no other charset)")
    try:
        body = json.loads((await request.read()).decode("utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError):
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
    access = request.app[ACCESS]
    if not access.rates.take(access.client(request)):
        return refuse(429, "too many commands: wait a second")
    answer = await request.app[EXECUTIVE].staff.submit(
        command, alert_id if isinstance(alert_id, str) else "", by=sender(request)
    )
    request.app[PAGES].changed.set()
    lang = asked_language(request)
    words = say(by_name(answer.words, request.app[EXECUTIVE].site), lang)
    if not answer.ok:
        return web.json_response({"ok": False, "reason": words, "language": lang}, status=409)
    return web.json_response({"ok": True, "did": words, "language": lang})


ROUTES = [
    web.get("/", get_page),
    web.get("/console.js", get_script),
    web.get("/favicon.ico", get_favicon),
    web.get("/api/words", get_words),
    web.get("/api/state", get_state),
    web.get("/api/site", get_site),
    web.get("/api/tree", get_tree),
    web.get("/api/stream", get_stream),
    web.post("/api/ticket", post_ticket),
    web.post("/api/command", post_command),
    web.post("/api/handover", post_handover),
    *PAIR_ROUTES,
    web.get("/ack/{alert_id}", get_ack, allow_head=False),  # shows; HEAD not even that
    web.post("/ack/{alert_id}", post_ack),  # the page's one button acknowledges
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
    await close_all(app[PAGES])


def make_app(
    executive: Executive,
    *,
    token: str | None,
    loopback: bool,
    origins: Origins | None = None,
    tell: Callable[[Handover], None] | None = None,
    devices: Devices | None = None,
) -> web.Application:
    """``executive``'s console as an application: its routes, its state, its lifetime.
    ``token`` (None: commands are off); ``loopback``: whether reads may need no token;
    ``origins``: the console's own (bound by :class:`Console` once it listens); ``tell``:
    where a shift's handover goes (the webhooks); ``devices``: the paired devices (None:
    pairing is off)."""
    cfg = executive.site.console
    app = web.Application(middlewares=[guard], client_max_size=cfg.max_body)
    app[EXECUTIVE] = executive
    app[ACCESS] = Access(
        token,
        loopback,
        cfg.max_body,
        Rates(cfg.commands_per_second),
        origins or Origins("127.0.0.1", executive.site.alerts.console_url),
        proxies=networks(cfg.trusted_proxies),
    )
    book = executive.staff.book
    shift = Shift(
        executive.site.staff.handover,
        lambda: [
            (a, a.id not in book.unacknowledged)
            for a in sorted(book.active.values(), key=lambda a: a.since)
        ],
        tell,
    )
    app[SHOWN] = Shown(Day(executive.site.language), shift, LogLines(owner=executive), StopClock())
    app[PAGES] = Pages(cfg.push_every)
    access = app[ACCESS]
    app[ACK_DESK] = AckDesk(
        executive,
        link_key(token) if token is not None else None,
        access.failures,
        access.rates,
        access.client,
        app[PAGES].changed.set,
    )
    app[PAIR_DESK] = PairDesk(
        devices or Devices(None),
        Pairings(executive.site.staff.pairing_ttl),
        token,
        access.failures,
        access.client,
        lambda request: public_url(executive.site.alerts.console_url, request),
        asked_language,
    )
    app[ASSETS] = load_assets()
    app.add_routes(ROUTES)
    app.cleanup_ctx.extend([log_lines, pusher])
    app.on_shutdown.append(close_pages)
    app.on_response_prepare.append(secure_headers)
    return app


class Console:
    """One executive's console on ``host:port`` (0: any free port, then :attr:`bound_port`):
    :meth:`attach` before the executive runs, :meth:`start` inside its loop, :meth:`close`
    on the way out. At most ``max_connections`` connections at once (and at most half the
    process's descriptors: :func:`~frog_bt.live.console.gate.connection_cap`)."""

    def __init__(
        self,
        executive: Executive,
        host: str,
        port: int,
        token: str | None = None,
        *,
        max_connections: int | None = None,
        header_timeout: float = HEADER_TIMEOUT,
        tell: Callable[[Handover], None] | None = None,
        devices: Devices | None = None,
    ) -> None:
        self.executive = executive
        self.host, self.port = host, port
        self.origins = Origins(host, executive.site.alerts.console_url)
        self.app = make_app(
            executive,
            token=token,
            loopback=is_loopback(host),
            origins=self.origins,
            tell=tell,
            devices=devices,
        )
        self.door = Door(connection_cap() if max_connections is None else max_connections)
        self.bound_port: int | None = None
        # bounded, with pages still open; keepalive_timeout is also the header deadline
        self._runner = web.AppRunner(
            self.app,
            access_log=None,
            handle_signals=False,
            shutdown_timeout=CLOSE_TIMEOUT,
            keepalive_timeout=header_timeout,
        )
        self._out_of_files: OutOfFiles | None = None
        self._started = False

    def attach(self) -> None:
        """The day's tally and the shift among the executive's observers."""
        kept = self.app[SHOWN]
        self.executive.observers.attach(self.executive, [kept.day, kept.shift])

    async def start(self) -> None:
        """Listen; OSError when the address cannot be bound (then :meth:`close`)."""
        self._started = True
        await self._runner.setup()
        site = GatedSite(self._runner, self.host, self.port, self.door)
        await site.start()
        self.bound_port = site.port
        self.origins.bound(site.port)
        self._out_of_files = OutOfFiles(asyncio.get_running_loop(), site.listening())
        log.info("console at %s", self.url)

    @property
    def url(self) -> str:
        """The console's address as a browser opens it (on 0.0.0.0: this machine's name)."""
        host = self.host
        if host in ("0.0.0.0", "", "::"):
            host = socket.gethostname() or "127.0.0.1"
        if ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{self.bound_port}/"

    async def close(self) -> None:
        """The pages closed, the open requests given :data:`CLOSE_TIMEOUT`, then the pusher
        and the log handler gone. Once; nothing to do when never started."""
        if self._started:
            self._started = False
            if self._out_of_files is not None:
                self._out_of_files.close()
            await self._runner.cleanup()
