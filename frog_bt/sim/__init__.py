"""The built-in simulator: a rosbridge v2 server playing the robot, and a UDP front end.

``frog-bt sim`` runs it from the command line (:mod:`frog_bt.sim.command`);
end-to-end tests start a :class:`Simulator` in-process::

    sim = Simulator(load_scenario("default"), rosbridge_port=0, frontend_port=0)
    await sim.start()
    await sim.wait_for(lambda r: r.channel == "/GotoWayPoint", timeout=10)
    await sim.stop()

Modules: :mod:`~frog_bt.sim.scenario` (YAML scenarios), :mod:`~frog_bt.sim.world`
(robot model: :mod:`~frog_bt.sim.navigation`, :mod:`~frog_bt.sim.docking`,
:mod:`~frog_bt.sim.people`, :mod:`~frog_bt.sim.faces`,
:mod:`~frog_bt.sim.diagnostics`), :mod:`~frog_bt.sim.msgs` (ROS message
builders), :mod:`~frog_bt.sim.rosbridge_protocol` (sans-I/O server) and
:mod:`~frog_bt.sim.rosbridge_server` (its asyncio adapter),
:mod:`~frog_bt.sim.frontend` and :mod:`~frog_bt.sim.frontend_udp` (front end),
:mod:`~frog_bt.sim.traffic` (message log), :mod:`~frog_bt.sim.site` (POI table),
:mod:`~frog_bt.sim.simulator`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from frog_bt.sim.scenario import (
        Scenario,
        builtin_scenarios,
        load_scenario,
        parse_scenario,
        scenario_from,
    )
    from frog_bt.sim.simulator import Simulator
    from frog_bt.sim.traffic import MessageLog, Record
    from frog_bt.sim.world import World

# Imported on first use, so that ``frog-bt --help`` does not load websockets and pydantic.
_EXPORTS = {
    "MessageLog": "frog_bt.sim.traffic",
    "Record": "frog_bt.sim.traffic",
    "Scenario": "frog_bt.sim.scenario",
    "Simulator": "frog_bt.sim.simulator",
    "World": "frog_bt.sim.world",
    "builtin_scenarios": "frog_bt.sim.scenario",
    "load_scenario": "frog_bt.sim.scenario",
    "parse_scenario": "frog_bt.sim.scenario",
    "scenario_from": "frog_bt.sim.scenario",
}
__all__ = [
    "MessageLog",
    "Record",
    "Scenario",
    "Simulator",
    "World",
    "builtin_scenarios",
    "load_scenario",
    "parse_scenario",
    "scenario_from",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'frog_bt.sim' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
