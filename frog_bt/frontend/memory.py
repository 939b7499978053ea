"""Datagrams in memory: UDP with no socket, for tests.

:class:`MemoryNet` has the one call of the event loop that the UDP adapters use,
``create_datagram_endpoint(protocol_factory, local_addr=...)``: the front-end link
(:class:`~frog_bt.frontend.link.FrontendLink` given ``network=``) and the simulated front
end (:class:`~frog_bt.sim.frontend_udp.FrontendSocket` given ``network=``) bind addresses
on it and send datagrams to each other's, delivered on the event loop (``call_soon``), in
order, as bytes. As with UDP, a datagram to an address nobody has bound is lost, and a
bound address is refused to a second endpoint (``EADDRINUSE``). The protocols on both
ends (:mod:`frog_bt.frontend.protocol`) run as they do over sockets.
"""

from __future__ import annotations

import asyncio
import errno
import itertools
import os
from collections.abc import Callable
from typing import Any

__all__ = ["MemoryNet"]

Address = tuple[str, int]


class _Transport(asyncio.DatagramTransport):
    """One bound address of a :class:`MemoryNet`."""

    def __init__(self, net: MemoryNet, address: Address, protocol: asyncio.DatagramProtocol):
        super().__init__()
        self._net = net
        self._address = address
        self._protocol = protocol
        self._closing = False

    def get_extra_info(self, name: str, default: Any = None) -> Any:
        return self._address if name == "sockname" else default

    def sendto(self, data: Any, addr: Any = None) -> None:
        if self._closing:
            return
        peer = self._net.bound.get((str(addr[0]), int(addr[1])))
        if peer is None:
            self._net.lost += 1
            return
        self._net.delivered += 1
        asyncio.get_running_loop().call_soon(peer._receive, bytes(data), self._address)

    def _receive(self, data: bytes, source: Address) -> None:
        if not self._closing:
            self._protocol.datagram_received(data, source)

    def is_closing(self) -> bool:
        return self._closing

    def close(self) -> None:
        if self._closing:
            return
        self._closing = True
        if self._net.bound.get(self._address) is self:
            del self._net.bound[self._address]
        asyncio.get_running_loop().call_soon(self._protocol.connection_lost, None)

    def abort(self) -> None:
        self.close()


class MemoryNet:
    """In-process datagram addresses; see the module docstring."""

    def __init__(self) -> None:
        self.bound: dict[Address, _Transport] = {}
        self.delivered = 0
        self.lost = 0  # sent to an address nobody had bound
        self._ports = itertools.count(40000)

    async def create_datagram_endpoint(
        self,
        protocol_factory: Callable[[], asyncio.DatagramProtocol],
        local_addr: Address | None = None,
    ) -> tuple[asyncio.DatagramTransport, asyncio.DatagramProtocol]:
        """Bind ``local_addr`` (port 0: a free one) to a new protocol, as the event loop's
        call of the same name does."""
        host, port = local_addr or ("127.0.0.1", 0)
        if port == 0:
            port = next(p for p in self._ports if (host, p) not in self.bound)
        address = (host, int(port))
        if address in self.bound:
            raise OSError(errno.EADDRINUSE, os.strerror(errno.EADDRINUSE))
        protocol = protocol_factory()
        transport = _Transport(self, address, protocol)
        self.bound[address] = transport
        protocol.connection_made(transport)
        return transport, protocol
