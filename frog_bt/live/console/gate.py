"""The console's door: at most so many connections at once, a plain 503 beyond, and one
log line (not a traceback per attempt) when the process runs out of file descriptors;
aiohttp's own error answers made the console's (:class:`SafeErrors`).

:class:`GatedSite` is an aiohttp site (``web.BaseSite``, as ``TCPSite``) whose server
hands each connection to :class:`Gate` first: under the cap, the connection goes on to
aiohttp's own protocol (``runner.server()``), which sees every call the transport makes;
over it, the connection gets ``503`` and is closed at once, so a flood cannot hold more
descriptors than the cap. The header-read timeout is aiohttp's ``keepalive_timeout``,
which closes a connection that has not sent a whole request header in time (pinned by
``tests/console/test_load.py``).

When ``accept()`` fails for want of descriptors, asyncio reports it to the loop's
exception handler once per attempt, with a traceback; :class:`OutOfFiles` takes those
reports for this console's socket and logs one line a minute with a count.
"""

from __future__ import annotations

import asyncio
import errno
import logging
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from aiohttp import web

from frog_bt.warning_limit import WarningLimiter

log = logging.getLogger(__name__)
MAX_CONNECTIONS = 512  # connections at once (also at most half the descriptors)
# what every answer carries, the ones aiohttp and the gate write themselves too
BARE_HEADERS = {
    "Content-Security-Policy": "default-src 'none'; frame-ancestors 'none'",
    "X-Content-Type-Options": "nosniff",
    "X-Frame-Options": "DENY",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-store",
}
PLAIN_503 = (
    b"HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain\r\n"
    + b"".join(f"{k}: {v}\r\n".encode() for k, v in BARE_HEADERS.items())
    + b"Content-Length: 30\r\nConnection: close\r\n\r\n"
    + b"the console is busy: try again"
)
ERRORS = {  # what aiohttp's own error answers say: fixed words, never the request's bytes
    400: "the request could not be read (malformed, or a header too long)",
    500: "the console failed to answer: see its log",
    504: "the console took too long to answer",
}
OUT_OF_FILES = {errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM}


def connection_cap(limit: int = MAX_CONNECTIONS) -> int:
    """``limit``, but at most half the descriptors this process may open: the tour's own
    links, recordings and logs keep the other half."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    return limit if soft == resource.RLIM_INFINITY else max(8, min(limit, soft // 2))


def accept_burst(cap: int, most: int = 128) -> int:
    """The listen backlog for a door of ``cap``: asyncio accepts up to the backlog's count
    of connections in one turn before any reaches its :class:`Gate`, so that many
    descriptors are held on top of the cap for a moment. A quarter of what the cap leaves
    to the tour keeps a flood from taking the rest (a module imported at that moment
    failed for want of descriptors)."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return most
    return max(1, min(most, (soft - cap) // 4))


@dataclass
class Door:
    """How many connections are open, how many may be, how many were turned away, and how
    many requests aiohttp's HTTP layer answered with an error."""

    cap: int
    open: int = 0
    refused: int = 0
    errors: int = 0  # answered by aiohttp's HTTP layer (:class:`SafeErrors`)
    warnings: WarningLimiter = field(default_factory=lambda: WarningLimiter(60.0, logger=log))


class SafeErrors(web.RequestHandler):
    """aiohttp's protocol, with its own error answers made the console's. aiohttp answers
    a request it cannot parse (a header over 8,190 bytes, a duplicate ``Host``, a bad
    byte), a handler that raised or timed out, before and outside the application: no
    middleware and no ``on_response_prepare`` runs, and its text repeats what it could
    not parse. Here :meth:`handle_error` answers fixed words (:data:`ERRORS`) as the
    console's JSON refusal with :data:`BARE_HEADERS`, counts it in its :class:`Door`, and
    logs one line a minute with no byte of the request. ``__slots__ = ()``: the same
    layout as aiohttp's class, so :class:`Gate` turns the protocol ``runner.server()``
    makes into this one (pinned by ``tests/console/test_raw_errors.py``)."""

    __slots__ = ()

    def handle_error(
        self,
        request: web.BaseRequest,
        status: int = 500,
        exc: BaseException | None = None,
        message: str | None = None,
    ) -> web.StreamResponse:
        transport = request.transport
        gate = transport.get_protocol() if transport is not None else None
        if isinstance(gate, Gate):  # this console's door counts them
            door = gate.door
            door.errors += 1
            door.warnings.warn(
                str(status),
                f"console: {door.errors} request{'s' if door.errors != 1 else ''} answered "
                f"{status} by the HTTP layer so far (the last: "
                f"{type(exc).__name__ if exc else 'no exception'})",
            )
        if status >= 500 and exc is not None:
            log.error("console: a request failed", exc_info=exc)
        if request.writer.output_size > 0:  # as aiohttp: a half-sent answer cannot change
            raise ConnectionError("an answer was partly sent already")
        text = ERRORS.get(status, "the request could not be handled")
        response = web.json_response(
            {"ok": False, "reason": text}, status=status, headers=BARE_HEADERS
        )
        response.force_close()
        return response


class Gate(asyncio.Protocol):
    """One connection: passed on to ``inner`` (aiohttp's protocol) under the cap."""

    def __init__(self, door: Door, make_inner: Callable[[], asyncio.Protocol]) -> None:
        self.door = door
        self.make_inner = make_inner
        self.inner: asyncio.Protocol | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        if self.door.open >= self.door.cap:
            self.door.refused += 1
            assert isinstance(transport, asyncio.WriteTransport)
            transport.write(PLAIN_503)
            transport.close()
            return
        self.door.open += 1
        self.inner = self.make_inner()
        if type(self.inner) is web.RequestHandler:
            self.inner.__class__ = SafeErrors  # the console's answers to aiohttp's errors
        self.inner.connection_made(transport)

    def data_received(self, data: bytes) -> None:
        if self.inner is not None:
            self.inner.data_received(data)

    def eof_received(self) -> bool | None:
        return self.inner.eof_received() if self.inner is not None else None

    def connection_lost(self, exc: Exception | None) -> None:
        if self.inner is not None:
            self.door.open -= 1
            inner, self.inner = self.inner, None
            inner.connection_lost(exc)

    def pause_writing(self) -> None:
        if self.inner is not None:
            self.inner.pause_writing()

    def resume_writing(self) -> None:
        if self.inner is not None:
            self.inner.resume_writing()


class GatedSite(web.BaseSite):
    """``host:port`` (0: any free port, then :attr:`port`), through a :class:`Door`."""

    def __init__(self, runner: web.BaseRunner, host: str, port: int, door: Door) -> None:
        super().__init__(runner, backlog=accept_burst(door.cap))
        self._host, self._port, self.door = host, port, door

    @property
    def name(self) -> str:
        return f"http://{self._host}:{self._port}"

    @property
    def port(self) -> int:
        return self._port

    async def start(self) -> None:
        await super().start()
        make_inner = self._runner.server
        assert make_inner is not None
        loop = asyncio.get_running_loop()
        server = await loop.create_server(
            lambda: Gate(self.door, make_inner), self._host, self._port, backlog=self._backlog
        )
        self._server = server
        self.sockets: list[Any] = list(server.sockets)
        if self.sockets:
            self._port = int(self.sockets[0].getsockname()[1])

    def listening(self) -> list[Any]:
        return list(getattr(self, "sockets", []))


class OutOfFiles:
    """The loop's exception handler while the console runs: ``accept()`` failing for want
    of descriptors on one of ``sockets`` is one log line a minute with a count; anything
    else goes to the handler that was there before."""

    def __init__(self, loop: asyncio.AbstractEventLoop, sockets: list[Any]) -> None:
        self.loop = loop
        self.filenos = {s.fileno() for s in sockets}  # asyncio reports a new wrapper each time
        self.before = loop.get_exception_handler()
        self.count = 0
        self.logged_at: float | None = None
        loop.set_exception_handler(self)

    def __call__(self, loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        if (
            isinstance(exc, OSError)
            and exc.errno in OUT_OF_FILES
            and _fileno(context.get("socket")) in self.filenos
        ):
            self.count += 1
            now = time.monotonic()
            if self.logged_at is None or now - self.logged_at >= 60.0:
                log.error(
                    "console: out of file descriptors (%s): %d connection%s not accepted; "
                    "asyncio retries each second",
                    errno.errorcode.get(exc.errno or 0, exc.errno),
                    self.count,
                    "" if self.count == 1 else "s",
                )
                self.count, self.logged_at = 0, now
            return
        if self.before is not None:
            self.before(loop, context)
        else:
            loop.default_exception_handler(context)

    def close(self) -> None:
        """The previous handler back (only if nobody replaced this one meanwhile)."""
        if self.loop.get_exception_handler() is self:
            self.loop.set_exception_handler(self.before)


def _fileno(sock: Any) -> int | None:
    try:
        return int(sock.fileno())
    except (AttributeError, OSError, ValueError):
        return None
