"""The simulated front end's UDP socket: a thin asyncio adapter that only moves bytes.

Listens on ``host:port`` (port 0: any free port, see :attr:`FrontendSocket.port`)
and sends to the executive's address; over a
:class:`~frog_bt.frontend.memory.MemoryNet` (``network``) instead of a socket in tests.
What the datagrams mean is :mod:`frog_bt.sim.frontend`'s business.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from frog_bt.frontend.link import DatagramNetwork

log = logging.getLogger(__name__)

Address = tuple[str, int]


class _Protocol(asyncio.DatagramProtocol):
    def __init__(self, on_datagram: Callable[[bytes, Address], None]) -> None:
        self.on_datagram = on_datagram

    def datagram_received(self, data: bytes, addr: Address) -> None:
        self.on_datagram(data, (addr[0], addr[1]))

    def error_received(self, exc: Exception) -> None:
        # ICMP port unreachable while the executive is not listening yet: expected.
        log.debug("front-end socket: %s", exc)


class FrontendSocket:
    """A UDP socket bound to ``host:port`` that sends to ``executive``."""

    def __init__(
        self,
        host: str,
        port: int,
        executive: Address,
        on_datagram: Callable[[bytes, Address], None],
        network: DatagramNetwork | None = None,
    ) -> None:
        self.network = network
        self.host = host
        self.port = port
        self.executive = executive
        self.on_datagram = on_datagram
        self._transport: asyncio.DatagramTransport | None = None
        self.send_errors = 0

    async def open(self) -> None:
        network: DatagramNetwork = self.network or asyncio.get_running_loop()
        transport, _ = await network.create_datagram_endpoint(
            lambda: _Protocol(self.on_datagram), local_addr=(self.host, self.port)
        )
        self._transport = transport
        self.port = transport.get_extra_info("sockname")[1]
        log.info(
            "front end listening on udp %s:%d, sending to %s:%d",
            self.host,
            self.port,
            *self.executive,
        )

    @property
    def address(self) -> Address | None:
        """(host, port) the socket is bound to; None when closed."""
        if self._transport is None:
            return None
        host, port = self._transport.get_extra_info("sockname")[:2]
        return host, port

    def send(self, data: bytes) -> None:
        if self._transport is None or self._transport.is_closing():
            return
        try:
            self._transport.sendto(data, self.executive)
        except OSError as exc:
            self.send_errors += 1
            log.debug("front-end send failed: %s", exc)

    def close(self) -> None:
        if self._transport is not None:
            self._transport.close()
            self._transport = None
