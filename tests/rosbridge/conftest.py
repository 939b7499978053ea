"""Test helpers: a minimal rosbridge-like server and a runner for coroutines.

:class:`FakeRosbridge` listens on 127.0.0.1 (port 0 unless told), records every
frame it receives (parsed JSON) and can push frames to its clients. Tests wait
on its queues and events, never on sleeps.
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import Coroutine
from typing import Any, TypeVar

from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.exceptions import ConnectionClosed
from websockets.protocol import State

T = TypeVar("T")

TEST_TIMEOUT = 10.0  # per test; a hang fails the test instead of the whole run


def run(coro: Coroutine[Any, Any, T], timeout: float = TEST_TIMEOUT) -> T:
    """Run a coroutine to completion in a fresh event loop, with a timeout."""

    async def guarded() -> T:
        async with asyncio.timeout(timeout):
            return await coro

    return asyncio.run(guarded())


class FakeRosbridge:
    """Just enough of rosbridge_server to test a client against."""

    def __init__(self, port: int = 0) -> None:
        self.port = port
        self.frames: list[dict[str, Any]] = []
        self.connections: list[ServerConnection] = []
        self._inbox: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
        self._connected = asyncio.Event()
        self._server: Server | None = None

    @property
    def url(self) -> str:
        return f"ws://127.0.0.1:{self.port}"

    async def start(self) -> FakeRosbridge:
        self._server = await serve(self._handler, "127.0.0.1", self.port)
        self.port = self._server.sockets[0].getsockname()[1]
        return self

    async def stop(self) -> None:
        """Close the listening socket and every connection (code 1001)."""
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()
            self._server = None

    async def __aenter__(self) -> FakeRosbridge:
        return await self.start()

    async def __aexit__(self, *exc: object) -> None:
        await self.stop()

    async def _handler(self, ws: ServerConnection) -> None:
        self.connections.append(ws)
        self._connected.set()
        try:
            async for text in ws:
                frame = json.loads(text)
                self.frames.append(frame)
                self._inbox.put_nowait(frame)
        except ConnectionClosed:
            pass

    async def next_frame(self) -> dict[str, Any]:
        return await self._inbox.get()

    async def take(self, n: int) -> list[dict[str, Any]]:
        """The next ``n`` frames received, in order."""
        return [await self._inbox.get() for _ in range(n)]

    async def push(self, frame: str | bytes | dict[str, Any]) -> None:
        """Send a frame to every open connection (waits for the first one)."""
        await self._connected.wait()
        data = json.dumps(frame) if isinstance(frame, dict) else frame
        for ws in self.connections:
            if ws.state is State.OPEN:
                await ws.send(data)

    async def publish(self, topic: str, msg: Any) -> None:
        await self.push({"op": "publish", "topic": topic, "msg": msg})


def free_port() -> int:
    """A loopback port nothing listens on (bound then released)."""
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])
