"""The front-end UDP link: a thin asyncio shell around :class:`Endpoint` (CONTRACT §2).

:class:`FrontendLink` owns one UDP socket, bound to ``listen``. It sends what it
originates to ``peer`` from that socket and answers every datagram with an ack
sent back to the datagram's source address. All protocol decisions (numbering,
acks, resends, duplicates, foreign hosts, malformed datagrams) are the
:class:`~frog_bt.frontend.protocol.Endpoint`'s; this module only moves bytes and
turns the injected :class:`~frog_bt.clock.Clock` into resend wake-ups.

The same class serves both sides:

* the executive: ``FrontendLink(("127.0.0.1", 5006), ("127.0.0.1", 5005), clock)``
  acts on events and sends commands;
* the simulated front end: ``FrontendLink(("127.0.0.1", 5005), ("127.0.0.1", 5006),
  clock, inbound=COMMANDS)`` acts on commands and sends events.

Resends run on the project clock (sim time in sim, the recording's time in
replay), never on the event loop's own clock.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import ipaddress
import logging
import socket
from collections.abc import Callable
from typing import Any, Protocol

from frog_bt.clock import Clock
from frog_bt.frontend.protocol import MAX_DATAGRAM, Endpoint, LinkStats
from frog_bt.model.frontend import EVENTS, FrontendMessage
from frog_bt.warning_limit import WarningLimiter

log = logging.getLogger(__name__)

Address = tuple[str, int]
# What a datagram came from: (host, port), and for IPv6 also (flowinfo, scope_id).
SockAddr = tuple[str, int, *tuple[int, ...]]
# (direction "in" | "out", datagram, clock time): a tap for recordings (CONTRACT §6).
DatagramTap = Callable[[str, bytes, float], None]
DRAIN_LIMIT = 256  # datagrams read per turn of the loop beyond the first (a flood cannot hold it)
READ_SIZE = 65536  # bytes: a whole UDP datagram, so that an oversized one is seen as such


class DatagramNetwork(Protocol):
    """Where datagram endpoints come from: the event loop (sockets), or a
    :class:`~frog_bt.frontend.memory.MemoryNet` in tests."""

    async def create_datagram_endpoint(
        self, protocol_factory: Callable[[], Any], local_addr: Address | None = None
    ) -> tuple[Any, Any]: ...


class FrontendPort(Protocol):
    """What the executive needs of its front-end link, handed to it ready-made: a
    :class:`FrontendLink` (over UDP, or over a :class:`~frog_bt.frontend.memory.MemoryNet`
    in tests), or any fake with this shape. The executive sets ``on_message`` (each new
    event) and ``on_datagram`` (each datagram in or out) before it calls :meth:`start`."""

    on_message: Callable[[FrontendMessage], None] | None
    on_datagram: DatagramTap | None
    last_heard: float | None

    @property
    def stats(self) -> LinkStats: ...
    @property
    def pending(self) -> int: ...
    @property
    def oldest_pending(self) -> float | None: ...

    def send(self, message: FrontendMessage) -> None: ...
    async def start(self) -> None: ...
    async def drain(self, timeout: float) -> bool: ...
    def close(self) -> None: ...
    async def wait_closed(self) -> None: ...


class AddressError(OSError):
    """The link cannot use an address: ``which`` is ``"listen"`` (cannot bind) or
    ``"peer"`` (cannot resolve the front end's host); the message says why."""

    def __init__(self, which: str, address: Address, reason: str) -> None:
        super().__init__(f"{address[0]}:{address[1]}: {reason}")
        self.which = which
        self.address = address
        self.reason = reason


class _DatagramProtocol(asyncio.DatagramProtocol):
    """Hands every datagram to the link. The event loop reads one datagram per turn, and
    a busy loop turns slowly (a rosbridge backlog, a tick, the recording), so a fresh
    event would wait behind every stale resend queued before it; so each turn also reads
    whatever else waits on the socket (up to :data:`DRAIN_LIMIT`), through a duplicate of
    the loop's socket. An endpoint with no socket (a MemoryNet's) delivers as it is."""

    def __init__(self, link: FrontendLink) -> None:
        self._link = link
        self._sock: socket.socket | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        sock = transport.get_extra_info("socket")
        if sock is not None:
            self._sock = sock.dup()
            self._sock.setblocking(False)

    def datagram_received(self, data: bytes, addr: SockAddr) -> None:
        self._link._datagram_received(data, addr)
        for _ in range(DRAIN_LIMIT):
            if self._sock is None or self._link._closing:
                return
            try:
                data, addr = self._sock.recvfrom(READ_SIZE)
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                self.error_received(exc)
                return
            self._link._datagram_received(data, addr)

    def error_received(self, exc: Exception) -> None:
        # ICMP errors (peer not listening yet) are expected; resends cover them.
        self._link._warnings.warn("socket error", f"front-end link socket error: {exc}")

    def connection_lost(self, exc: Exception | None) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        self._link._closed.set()


class FrontendLink:
    """One side of the front-end link over UDP.

    ``listen`` is the local address to bind (port 0 picks a free port, see
    :attr:`listen_port`); ``peer`` is where originated messages go, and its host
    is the only one whose datagrams are accepted. ``inbound`` is the table of
    message types this side acts on: :data:`~frog_bt.model.frontend.EVENTS`
    for the executive, :data:`~frog_bt.model.frontend.COMMANDS` for the front
    end. ``on_message`` is called with every accepted, non-duplicate message, on
    the event loop, after its ack has been sent. ``on_datagram`` (optional) sees
    every datagram received from the peer host (``"in"``, malformed and duplicate
    ones included; datagrams from other hosts are dropped and counted, never
    shown, so a recording holds nothing a replay must not act on) or sent
    (``"out"``, acks and resends included), stamped with the clock's time.
    ``network`` makes the endpoint (default: the event loop, a UDP socket; a
    :class:`~frog_bt.frontend.memory.MemoryNet` runs the same link with no socket).
    """

    def __init__(
        self,
        listen: Address,
        peer: Address,
        clock: Clock,
        *,
        inbound: dict[str, type[FrontendMessage]] = EVENTS,
        on_message: Callable[[FrontendMessage], None] | None = None,
        resend_after: float = 0.25,
        max_sends: int = 8,
        dedup_window: float = 10.0,
        on_datagram: DatagramTap | None = None,
        network: DatagramNetwork | None = None,
    ) -> None:
        if not resend_after > 0:
            raise ValueError(f"resend_after must be > 0, got {resend_after}")
        if max_sends < 1:
            raise ValueError(f"max_sends must be >= 1, got {max_sends}")
        self.listen = (listen[0], int(listen[1]))
        self.peer = (peer[0], int(peer[1]))
        self.clock = clock
        self.on_message = on_message
        self.on_datagram = on_datagram
        self.network = network
        self._endpoint = Endpoint(peer[0], inbound, resend_after, max_sends, dedup_window)
        self._peer_addr: Address = self.peer
        self._transport: asyncio.DatagramTransport | None = None
        self._resender: asyncio.Task[None] | None = None
        self._wakeup = asyncio.Event()
        self._sleeping_until: float | None = None
        self._closed = asyncio.Event()
        self._closing = False
        self._warnings = WarningLimiter(logger=log)
        self._settled = asyncio.Event()  # an ack arrived or a command was given up on
        self.last_heard: float | None = None  # project-clock time of the last datagram in

    # ------------------------------------------------------------ lifecycle

    async def start(self) -> None:
        """Bind the listen address and start the resend task."""
        if self._transport is not None or self._closing:
            raise RuntimeError("FrontendLink already started or closed")
        loop = asyncio.get_running_loop()
        network: DatagramNetwork = self.network or loop
        try:
            transport, _ = await network.create_datagram_endpoint(
                lambda: _DatagramProtocol(self), local_addr=self.listen
            )
        except OSError as exc:
            raise AddressError("listen", self.listen, "cannot listen there: " + _why(exc)) from exc
        self._transport = transport
        sock = transport.get_extra_info("socket")
        family = sock.family if sock is not None else socket.AF_INET
        try:
            host = await _resolve(loop, self.peer, family)
        except OSError as exc:
            self.close()
            raise AddressError("peer", self.peer, "cannot resolve the host: " + _why(exc)) from exc
        # Compare and send by IP: datagram sources are reported as IPs, never names.
        self._endpoint.peer_host = host
        self._peer_addr = (host, self.peer[1])
        self._resender = loop.create_task(self._resend_loop(), name="frontend-resend")
        self._resender.add_done_callback(_report_crash)
        log.info(
            "front-end link listening on %s:%d, peer %s:%d",
            self.listen[0],
            self.listen_port,
            *self.peer,
        )

    def close(self) -> None:
        """Stop resending and close the socket; idempotent. Pending commands are dropped."""
        if self._closing:
            return
        self._closing = True
        self._warnings.flush()  # what a flood's last datagrams were, told once
        if self._resender is not None:
            self._resender.cancel()
        if self._transport is not None:
            self._transport.close()
        else:
            self._closed.set()

    async def drain(self, timeout: float) -> bool:
        """Wait, at most ``timeout`` wall seconds, until every command sent has been acked
        or given up on (resends go on meanwhile); True when none is left.

        Called before :meth:`close` on shutdown, so that the last commands (``tour
        ended``, ``projector`` off, ``finish_poi``) reach the front end despite loss.
        """
        if self._transport is None or self._closing:
            return self._endpoint.pending == 0
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(timeout):
                while self._endpoint.pending:
                    self._settled.clear()
                    await self._settled.wait()
        return self._endpoint.pending == 0

    async def wait_closed(self) -> None:
        """Return once :meth:`close` has released the socket and the resend task."""
        if self._resender is not None:
            with contextlib.suppress(asyncio.CancelledError):
                await self._resender
        await self._closed.wait()

    # ------------------------------------------------------------ state

    @property
    def listen_port(self) -> int:
        """The bound UDP port (the real one when ``listen`` asked for port 0)."""
        if self._transport is None:
            raise RuntimeError("FrontendLink is not started")
        return int(self._transport.get_extra_info("sockname")[1])

    @property
    def stats(self) -> LinkStats:
        """Counters of the underlying :class:`Endpoint` (sent, acked, foreign, ...)."""
        return self._endpoint.stats

    @property
    def pending(self) -> int:
        """Messages sent and not yet acked or given up on."""
        return self._endpoint.pending

    @property
    def next_resend(self) -> float | None:
        """Project-clock time the next resend is due; None while nothing waits for an
        ack (then nothing is ever resent)."""
        return self._endpoint.next_deadline

    @property
    def oldest_pending(self) -> float | None:
        """When the oldest message waiting for its ack was first sent (None: none waits)."""
        return self._endpoint.oldest_pending

    # ------------------------------------------------------------ sending

    def send(self, message: FrontendMessage) -> None:
        """Send ``message`` to the peer now; it is resent until acked. Never blocks.

        Raises :class:`RuntimeError` before :meth:`start` and :class:`ValueError`
        for a message that cannot be encoded (NaN, larger than 8192 bytes). After
        :meth:`close` the message is dropped.
        """
        if self._closing:
            log.debug("front-end link closed, dropped %s", message.type)
            return
        if self._transport is None:
            raise RuntimeError("FrontendLink is not started")
        now = self.clock.now()
        data = self._endpoint.send(message, now)
        self._sendto(data, self._peer_addr, now)
        deadline = self._endpoint.next_deadline
        if deadline is not None and (
            self._sleeping_until is None or deadline < self._sleeping_until
        ):
            self._wakeup.set()

    def _sendto(self, data: bytes, addr: SockAddr, now: float) -> None:
        assert self._transport is not None
        self._transport.sendto(data, addr)
        if self.on_datagram is not None:
            self.on_datagram("out", data, now)

    async def _resend_loop(self) -> None:
        """Sleep on the project clock until the next resend is due, then poll."""
        while True:
            self._wakeup.clear()
            deadline = self._endpoint.next_deadline
            self._sleeping_until = deadline
            if deadline is None:
                await self._wakeup.wait()
                continue
            if deadline > self.clock.now() and not await self._sleep_or_wake(deadline):
                continue  # an earlier deadline arrived: recompute
            self._sleeping_until = None
            now = self.clock.now()
            pending = self._endpoint.pending
            for data in self._endpoint.poll(now):
                self._sendto(data, self._peer_addr, now)
            if self._endpoint.pending != pending:
                self._settled.set()  # given up on

    async def _sleep_or_wake(self, deadline: float) -> bool:
        """True once the clock reaches ``deadline``; False if woken earlier by :meth:`send`."""
        sleep = asyncio.ensure_future(self.clock.sleep_until(deadline))
        wake = asyncio.ensure_future(self._wakeup.wait())
        try:
            await asyncio.wait((sleep, wake), return_when=asyncio.FIRST_COMPLETED)
        finally:
            sleep.cancel()
            wake.cancel()
        return sleep.done() and not sleep.cancelled()

    # ------------------------------------------------------------ receiving

    def _datagram_received(self, data: bytes, addr: SockAddr) -> None:
        now = self.clock.now()
        if addr[0] == self._endpoint.peer_host:
            self.last_heard = now
            if self.on_datagram is not None:
                self.on_datagram("in", data, now)
        foreign = self._endpoint.stats.foreign
        received = self._endpoint.receive(data, addr[0], now)
        if received.acked is not None:
            self._settled.set()
        if received.reply is not None and not self._closing:
            self._sendto(received.reply, addr, now)
        if self._endpoint.stats.foreign != foreign:
            self._warnings.warn(
                "foreign",
                f"dropped a datagram from {addr[0]}:{addr[1]} "
                f"(front end is {self._endpoint.peer_host})",
            )
        if received.error is not None:
            size = f"{len(data)} bytes" if len(data) <= MAX_DATAGRAM else "oversized"
            self._warnings.warn(
                "malformed",
                f"malformed front-end datagram ({size}) from {addr[0]}:{addr[1]}: {received.error}",
            )
        if received.message is not None and self.on_message is not None:
            try:
                self.on_message(received.message)
            except Exception:
                log.exception("front-end message handler failed on %s", received.message.type)


async def _resolve(loop: asyncio.AbstractEventLoop, addr: Address, family: int) -> str:
    """The peer's IP as datagram sources report it (``localhost`` -> ``127.0.0.1``)."""
    host = addr[0]
    try:
        ipaddress.ip_address(host)
    except ValueError:
        infos = await loop.getaddrinfo(host, addr[1], family=family, type=socket.SOCK_DGRAM)
        if not infos:  # pragma: no cover - getaddrinfo raises instead
            raise OSError(f"cannot resolve front-end host {host!r}") from None
        return str(infos[0][4][0])
    return host


def _why(exc: OSError) -> str:
    text = exc.strerror or str(exc)
    if exc.errno == errno.EADDRINUSE:
        text += " (is another frog-bt or front end using it?)"
    return text


def _report_crash(task: asyncio.Task[None]) -> None:
    if not task.cancelled() and task.exception() is not None:
        log.error("front-end resend task failed", exc_info=task.exception())
