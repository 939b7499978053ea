"""Shared fixtures of the simulator tests: POI table, scenarios, worlds, async runner."""

from __future__ import annotations

import asyncio
import sys
from collections.abc import Callable, Coroutine
from pathlib import Path
from typing import Any, TypeVar

import pytest

from frog_bt.sim.scenario import Scenario, parse_scenario
from frog_bt.sim.site import PoiPose, load_pois
from frog_bt.sim.world import World

T = TypeVar("T")

# Test helpers (sim_clients.py, roslibpy_client.py) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))


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
