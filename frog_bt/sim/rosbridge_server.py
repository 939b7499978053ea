"""The simulator's rosbridge WebSocket server: a thin asyncio adapter over websockets.

It accepts connections, feeds each text frame to the sans-I/O
:class:`~frog_bt.sim.rosbridge_protocol.BridgeServer` and carries out what it
returns: frames go into a per-client queue drained by one writer task (frames
stay in order; a client too slow to keep up loses the oldest, counted in
:attr:`RosbridgeServer.dropped`), publishes from clients go to
``on_incoming``, ``Close`` closes the connection. Given a
:class:`~frog_bt.rosbridge.memory.MemoryWire`, it serves on that instead of a socket
(clients connect with the wire's ``connect``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from websockets.asyncio.server import serve
from websockets.exceptions import ConnectionClosed

from frog_bt.rosbridge.memory import MemoryWire
from frog_bt.rosbridge.protocol import MAX_FRAME_BYTES
from frog_bt.sim.rosbridge_protocol import Action, BridgeServer, Close, Incoming, Send

log = logging.getLogger(__name__)

QUEUE_LIMIT = 10_000  # frames waiting for one client


@dataclass(slots=True)
class _Connection:
    ws: Any  # a websockets ServerConnection, or a MemoryConnection
    queue: asyncio.Queue[str | Close]


class RosbridgeServer:
    """Listens on ``host:port`` (0: any free port; :attr:`port` gives the bound one)."""

    def __init__(
        self,
        protocol: BridgeServer,
        host: str,
        port: int,
        on_incoming: Callable[[Incoming], None],
        now: Callable[[], float],
        wire: MemoryWire | None = None,
    ) -> None:
        self.protocol = protocol
        self.wire = wire
        self.host = host
        self.port = port
        self.on_incoming = on_incoming
        self.now = now
        self.dropped = 0
        self._server: Any = None  # websockets' Server, or a MemoryServing
        self._connections: dict[int, _Connection] = {}

    @classmethod
    def relay(cls, host: str, port: int, secret: str | None = None) -> RosbridgeServer:
        """A server with no robot inside (``frog-bt sim --relay``): a publish from one
        client goes to every client subscribed to its topic, as in rosbridge_suite."""
        return cls(BridgeServer(secret), host, port, lambda _incoming: None, time.time)

    @property
    def listening(self) -> bool:
        return self._server is not None

    @property
    def addresses(self) -> list[tuple[str, int]]:
        """(host, port) of every socket it listens on (none when stopped)."""
        if self._server is None:
            return []
        names = [sock.getsockname() for sock in self._server.sockets]
        return [(str(name[0]), int(name[1])) for name in names]

    async def start(self) -> None:
        """Listen (again: on the port bound the first time)."""
        if self._server is not None:
            return
        if self.wire is not None:
            self._server = await self.wire.serve(self._handle)
            self.port = self.wire.port
            log.info("rosbridge serving in memory on %s", self.wire.url)
            return
        # No permessage-deflate: loopback needs no compression, and it costs per frame.
        self._server = await serve(
            self._handle, self.host, self.port, max_size=MAX_FRAME_BYTES, compression=None
        )
        self.port = next(iter(self._server.sockets)).getsockname()[1]
        log.info("rosbridge listening on ws://%s:%d", self.host, self.port)

    async def stop(self) -> None:
        """Drop every client and stop listening."""
        server, self._server = self._server, None
        if server is None:
            return
        server.close(close_connections=True)
        await server.wait_closed()
        log.info("rosbridge stopped listening")

    def publish(self, topic: str, msg: object) -> None:
        """Send one publish to every client subscribed to ``topic``."""
        self.dispatch(self.protocol.publish(topic, msg, self.now()))

    def dispatch(self, actions: Sequence[Action]) -> None:
        for action in actions:
            if isinstance(action, Send):
                self._enqueue(action.client, action.text)
            elif isinstance(action, Incoming):
                self.on_incoming(action)
            elif isinstance(action, Close):
                self._enqueue(action.client, action)

    def _enqueue(self, client: int, item: str | Close) -> None:
        conn = self._connections.get(client)
        if conn is None:
            return
        if conn.queue.qsize() >= QUEUE_LIMIT:
            conn.queue.get_nowait()
            self.dropped += 1
        conn.queue.put_nowait(item)

    async def _handle(self, ws: Any) -> None:  # a ServerConnection, or a MemoryConnection
        client = self.protocol.connect()
        conn = _Connection(ws, asyncio.Queue())
        self._connections[client] = conn
        log.info("rosbridge client %d connected from %s", client, ws.remote_address)
        writer = asyncio.create_task(self._write(conn))
        try:
            async for frame in ws:
                self.dispatch(self.protocol.receive(client, frame, self.now()))
        except ConnectionClosed:
            pass
        finally:
            self.protocol.disconnect(client)
            self._connections.pop(client, None)
            writer.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await writer
            log.info("rosbridge client %d disconnected", client)

    async def _write(self, conn: _Connection) -> None:
        try:
            while True:
                item = await conn.queue.get()
                if isinstance(item, Close):
                    await conn.ws.close(1008, item.reason)
                    return
                await conn.ws.send(item)
        except (ConnectionClosed, ConnectionResetError):  # the latter: in memory
            return
