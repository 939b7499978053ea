"""The simulated robot as a rosbridge *client* of an existing server (``frog-bt sim --via``).

Instead of serving rosbridge itself, the simulator connects to a rosbridge server
(a real rosbridge_suite, or ``frog-bt sim --relay``), advertises and publishes what
the robot publishes (``/clock`` and the executive's inputs) and subscribes to the
executive's commands. The executive connects to the same server: a real server then
sits between the executive and the simulated robot.

It has the shape of :class:`~frog_bt.sim.rosbridge_server.RosbridgeServer` that the
:class:`~frog_bt.sim.simulator.Simulator` uses (``start``, ``stop``, ``publish``),
over the executive's own :class:`~frog_bt.rosbridge.client.RosbridgeClient`: it
reconnects with backoff, authenticates (rosauth) when given a secret, and on every
connection advertises and subscribes again. What the robot publishes while the
server is away waits in the client's bounded queue; ``/clock`` is not queued (a
stale clock is worse than none: the next step publishes a fresh one).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from typing import Any

import msgspec

from frog_bt.rosbridge.client import RosbridgeClient
from frog_bt.rosbridge.link import LinkState
from frog_bt.sim.rosbridge_protocol import Incoming

log = logging.getLogger(__name__)

VIA_CLIENT = 0  # the client id an Incoming from the server carries


class RosbridgeVia:
    """The robot's side of the wire, as a client of the server at ``url``.

    ``publishes``: topic -> ROS type the robot advertises and publishes;
    ``commands``: topic -> ROS type of the executive's commands, handed to
    ``on_incoming`` as :class:`Incoming` (client :data:`VIA_CLIENT`).
    """

    def __init__(
        self,
        url: str,
        publishes: Mapping[str, str],
        commands: Mapping[str, str],
        on_incoming: Callable[[Incoming], None],
        *,
        secret: str | None = None,
    ) -> None:
        self.url = url
        self.publishes = dict(publishes)
        self.commands = dict(commands)
        self.on_incoming = on_incoming
        self.connections = 0  # times the link came up
        self.received = 0
        self.malformed = 0
        self.lost = 0  # published while the server was away
        self._client = RosbridgeClient(
            url, secret=secret, on_raw=self._on_raw, on_link=self._on_link, backoff_max=2.0
        )
        for topic, type_ in self.publishes.items():
            self._client.advertise(topic, type_)
        for topic, type_ in self.commands.items():
            self._client.subscribe(topic, type_)

    @property
    def port(self) -> int:
        return 0  # listens on nothing

    @property
    def addresses(self) -> list[tuple[str, int]]:
        return []

    @property
    def link(self) -> LinkState:
        return self._client.link

    async def start(self) -> None:
        """Start connecting (and reconnecting for ever); returns at once."""
        self._client.start()

    async def wait_connected(self, timeout: float) -> bool:
        return await self._client.wait_connected(timeout)

    async def stop(self) -> None:
        await self._client.close()

    def publish(self, topic: str, msg: Any) -> None:
        """Publish as the robot; while the server is away, lost (counted)."""
        if not self._client.link.connected:
            self.lost += 1
            return
        self._client.publish(topic, msg)

    # ------------------------------------------------------------ inbound

    def _on_raw(self, topic: str, raw: Any) -> None:
        if topic not in self.commands:
            return
        try:
            msg = msgspec.json.decode(raw) if isinstance(raw, msgspec.Raw | bytes | str) else raw
        except msgspec.DecodeError:
            self.malformed += 1
            return
        if not isinstance(msg, dict):
            self.malformed += 1
            return
        self.received += 1
        self.on_incoming(Incoming(VIA_CLIENT, topic, msg))

    def _on_link(self, state: LinkState) -> None:
        if state.connected:
            self.connections += 1
            log.info("sim: connected to rosbridge %s (connection %d)", self.url, self.connections)
        else:
            log.info("sim: rosbridge %s lost (%s)", self.url, state.last_error or "closed")
