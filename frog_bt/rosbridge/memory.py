"""A rosbridge wire in memory: WebSocket connections with no socket, for tests.

:class:`MemoryWire` stands for one server address. A server
(:class:`~frog_bt.sim.rosbridge_server.RosbridgeServer` given ``wire=``) serves on it
with :meth:`MemoryWire.serve`, and a client
(:class:`~frog_bt.rosbridge.client.RosbridgeClient` given ``connect=wire.connect``)
connects with :meth:`MemoryWire.connect`. Both sides then hold a
:class:`MemoryConnection` with the part of websockets' connection they use: ``send``,
``async for`` over the frames received, ``close``, ``close_code``, ``close_reason`` and the
addresses. Frames are the same JSON texts a socket would carry, delivered in order on the
event loop, so the sans-I/O protocols on both ends run as they do over a socket; only
the kernel and the WebSocket framing are left out (as httpx's ``MockTransport`` hands a
client its network).

A connection closed by either side ends the other side's ``async for``; a ``send`` on a
closed connection raises :class:`ConnectionResetError`, as a socket's would. Connecting
while nothing serves raises :class:`ConnectionRefusedError`; :meth:`MemoryServing.close`
drops every connection, so reconnects can be tested as well.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
from collections.abc import AsyncIterator, Awaitable, Callable

__all__ = ["MemoryConnection", "MemoryServing", "MemoryWire"]

_CLOSED = object()  # the end of one side's frames
_wires = itertools.count(1)


class MemoryConnection:
    """One end of an in-memory WebSocket connection."""

    def __init__(self, local: tuple[str, int], remote: tuple[str, int]) -> None:
        self.local_address = local
        self.remote_address = remote
        self.close_code: int | None = None
        self.close_reason = ""
        self.peer: MemoryConnection | None = None
        self._inbox: asyncio.Queue[object] = asyncio.Queue()

    @property
    def closed(self) -> bool:
        return self.close_code is not None

    async def send(self, text: str) -> None:
        """Deliver ``text`` to the other end; ConnectionResetError once closed."""
        if self.closed or self.peer is None:
            raise ConnectionResetError("in-memory connection closed")
        self.peer._inbox.put_nowait(text)

    def __aiter__(self) -> AsyncIterator[str]:
        return self._frames()

    async def _frames(self) -> AsyncIterator[str]:
        while True:
            item = await self._inbox.get()
            if item is _CLOSED:
                return
            assert isinstance(item, str)
            yield item

    async def close(self, code: int = 1000, reason: str = "") -> None:
        """Close both ends (idempotent): each side's ``async for`` ends."""
        for end in (self, self.peer):
            if end is not None and not end.closed:
                end.close_code, end.close_reason = code, reason
                end._inbox.put_nowait(_CLOSED)


Handler = Callable[[MemoryConnection], Awaitable[None]]


class MemoryServing:
    """A server serving on a :class:`MemoryWire` (as websockets' ``Server``)."""

    def __init__(self, wire: MemoryWire, handler: Handler) -> None:
        self.wire = wire
        self.handler = handler
        self.sockets: list[object] = []  # none: nothing listens on the machine
        self._tasks: set[asyncio.Task[None]] = set()
        self._connections: set[MemoryConnection] = set()

    def accept(self, server_end: MemoryConnection) -> None:
        self._connections.add(server_end)
        task = asyncio.get_running_loop().create_task(self._run(server_end))
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _run(self, end: MemoryConnection) -> None:
        try:
            await self.handler(end)
        finally:  # as websockets: the connection closes when its handler returns
            self._connections.discard(end)
            await end.close()

    def close(self, close_connections: bool = True) -> None:
        """Stop serving; drop every connection (``close_connections``)."""
        if self.wire.serving is self:
            self.wire.serving = None
        if close_connections:
            for end in list(self._connections):
                asyncio.get_running_loop().create_task(end.close(1001, "going away"))

    async def wait_closed(self) -> None:
        """Return once every connection's handler has returned."""
        while self._tasks:
            await asyncio.wait(set(self._tasks))


class MemoryWire:
    """One in-memory server address, served by at most one server at a time."""

    def __init__(self, host: str = "127.0.0.1") -> None:
        self.host = host
        self.port = next(_wires)  # a name for the logs, not a port on the machine
        self.url = f"ws://memory-{self.port}"
        self.serving: MemoryServing | None = None
        self.connections = 0  # connections accepted in all
        self._clients = itertools.count(1)

    async def serve(self, handler: Handler) -> MemoryServing:
        """Serve ``handler`` (called with each new connection's server end)."""
        if self.serving is not None:
            raise OSError(f"{self.url} is already served")
        self.serving = MemoryServing(self, handler)
        return self.serving

    @contextlib.asynccontextmanager
    async def connect(self, url: str) -> AsyncIterator[MemoryConnection]:
        """Connect to the server serving now (as websockets' ``connect``, an async
        context manager; the connection closes on exit)."""
        serving = self.serving
        if serving is None:
            raise ConnectionRefusedError(f"{url}: nothing serves the in-memory wire")
        client = (self.host, 50000 + next(self._clients))
        here = MemoryConnection(client, (self.host, self.port))
        there = MemoryConnection((self.host, self.port), client)
        here.peer, there.peer = there, here
        self.connections += 1
        serving.accept(there)
        try:
            yield here
        finally:
            await here.close()
