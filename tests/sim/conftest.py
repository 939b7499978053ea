"""Shared fixtures of the simulator tests: POI table, scenarios, worlds, async runner."""

from __future__ import annotations

import asyncio
import json
from collections.abc import Awaitable, Callable, Coroutine
from typing import Any, TypeVar

import pytest
from websockets.asyncio.client import ClientConnection, connect

from frog_bt.sim.scenario import Scenario, parse_scenario
from frog_bt.sim.site import PoiPose, load_pois
from frog_bt.sim.world import World

T = TypeVar("T")


@pytest.fixture(scope="session")
def pois() -> dict[str, PoiPose]:
    return load_pois()


@pytest.fixture
def scenario() -> Callable[..., Scenario]:
    """``scenario(visitors=[...], ...)``: a validated scenario from keyword arguments."""

    def make(**data: Any) -> Scenario:
        return parse_scenario(data, "<test>")

    return make


@pytest.fixture
def world(pois: dict[str, PoiPose], scenario: Callable[..., Scenario]) -> Callable[..., World]:
    """``world(**scenario_keys)``: a World at the scenario's start."""

    def make(**data: Any) -> World:
        return World(scenario(**data), pois)

    return make


@pytest.fixture
def arun() -> Callable[[Coroutine[Any, Any, T]], T]:
    """Run a coroutine to completion with a 20 s wall-clock safety net."""

    def run(coro: Coroutine[Any, Any, T]) -> T:
        async def guarded() -> T:
            return await asyncio.wait_for(coro, 20.0)

        return asyncio.run(guarded())

    return run


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

    async def next_publish(self, topic: str,
                           check: Callable[[dict[str, Any]], bool] = lambda msg: True,
                           ) -> dict[str, Any]:
        """The ``msg`` of the next publish on ``topic`` that passes ``check``."""
        frame = await self.next(lambda f: f.get("op") == "publish" and f.get("topic") == topic
                                and check(f["msg"]))
        return frame["msg"]

    async def close(self) -> None:
        await self.ws.close()


@pytest.fixture
def ros_client() -> Callable[[int], Awaitable[RosClient]]:
    return RosClient.open
