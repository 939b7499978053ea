"""Test-side peers of the simulator: a bare rosbridge client and the executive's UDP end."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Callable
from typing import Any

from websockets.asyncio.client import ClientConnection, connect

from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import frontend as fm

HOST = "127.0.0.1"


class RosClient:
    """A bare rosbridge client for tests: send ops, await the frames that match."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws

    @classmethod
    async def open(cls, port: int) -> RosClient:
        return cls(await connect(f"ws://127.0.0.1:{port}"))

    async def send(self, **frame: Any) -> None:
        await self.ws.send(json.dumps(frame))

    async def subscribe(self, topic: str, type_: str = "") -> None:
        await self.send(op="subscribe", id=f"subscribe:{topic}", topic=topic, type=type_)

    async def publish(self, topic: str, msg: dict[str, Any]) -> None:
        await self.send(op="publish", id=f"publish:{topic}", topic=topic, msg=msg)

    async def next(self, predicate: Callable[[dict[str, Any]], bool]) -> dict[str, Any]:
        """The next frame satisfying ``predicate`` (the others are skipped)."""
        while True:
            frame = json.loads(await self.ws.recv())
            if predicate(frame):
                return frame

    async def next_publish(
        self,
        topic: str,
        check: Callable[[dict[str, Any]], bool] = lambda msg: True,
    ) -> dict[str, Any]:
        """The ``msg`` of the next publish on ``topic`` that passes ``check``."""
        frame = await self.next(
            lambda f: f.get("op") == "publish" and f.get("topic") == topic and check(f["msg"])
        )
        return frame["msg"]

    async def close(self) -> None:
        await self.ws.close()


class Executive(asyncio.DatagramProtocol):
    """The executive's side of the front-end link: acks events, queues them."""

    def __init__(self) -> None:
        self.endpoint = Endpoint(HOST, fm.EVENTS)
        self.events: asyncio.Queue[fm.FrontendMessage] = asyncio.Queue()
        self.transport: asyncio.DatagramTransport | None = None
        self.frontend: tuple[str, int] = (HOST, 0)

    @classmethod
    async def open(cls) -> Executive:
        loop = asyncio.get_running_loop()
        _, exe = await loop.create_datagram_endpoint(cls, local_addr=(HOST, 0))
        return exe

    @property
    def port(self) -> int:
        assert self.transport is not None
        return self.transport.get_extra_info("sockname")[1]

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]

    def datagram_received(self, data: bytes, addr: Any) -> None:
        got = self.endpoint.receive(data, addr[0], 0.0)
        if got.reply is not None and self.transport is not None:
            self.transport.sendto(got.reply, addr)
        if got.message is not None:
            self.events.put_nowait(got.message)

    def send(self, message: fm.FrontendMessage) -> None:
        assert self.transport is not None
        self.transport.sendto(self.endpoint.send(message, 0.0), self.frontend)

    def close(self) -> None:
        if self.transport is not None:
            self.transport.close()
