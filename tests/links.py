"""Links to hand an executive in tests: over sockets, or fakes with no wire at all.

The executive takes its links ready-made (:class:`~frog_bt.rosbridge.link.RobotLink`,
:class:`~frog_bt.frontend.link.FrontendPort`). :func:`over_sockets` builds the real ones,
as ``frog-bt run`` does; :class:`FakeRobot` and :class:`FakeFrontend` have the same shape
and only record what the executive sends and hand it what a test feeds (for a whole
simulated tour without sockets, a rehearsal with ``memory=True`` runs the real links over
memory instead).
"""

from __future__ import annotations

import time
from typing import Any

from frog_bt.clock import Clock
from frog_bt.config import Site
from frog_bt.frontend.link import DatagramTap, FrontendLink
from frog_bt.frontend.protocol import LinkStats
from frog_bt.model.frontend import EVENTS, FrontendMessage
from frog_bt.model.ros import ROS_TYPES
from frog_bt.rosbridge.client import RosbridgeClient
from frog_bt.rosbridge.link import ClientStats, LinkState
from frog_bt.runtime.executive import Executive
from frog_bt.tree.loader import LoadedTree


def over_sockets(
    site: Site,
    tree: LoadedTree,
    clock: Clock,
    *,
    url: str,
    frontend: tuple[str, int],
    listen: tuple[str, int],
    sim_time: bool = False,
    secret: str | None = None,
) -> Executive:
    """An executive handed a rosbridge client of ``url`` and a UDP link (as ``run`` builds)."""
    client = RosbridgeClient(url, secret=secret)
    link = FrontendLink(listen, frontend, clock, inbound=EVENTS)
    return Executive(site, tree, clock, client, link, sim_time=sim_time)


class FakeRobot:
    """A :class:`~frog_bt.rosbridge.link.RobotLink` with no wire: what the executive
    sends is kept, what a test feeds (:meth:`feed`) is decoded as the client would and
    handed to the executive."""

    def __init__(self, url: str = "fake://robot") -> None:
        self.url = url
        self.on_input: Any = None
        self.on_link: Any = None
        self.advertised: dict[str, str] = {}
        self.subscribed: dict[str, str] = {}
        self.published: list[tuple[str, Any]] = []
        self.left = False
        self.closed = False
        self._link = LinkState(connected=False, since=time.monotonic())
        self._stats = ClientStats()

    @property
    def link(self) -> LinkState:
        return self._link

    @property
    def stats(self) -> ClientStats:
        return self._stats

    def advertise(self, topic: str, type: str) -> None:
        self.advertised[topic] = type

    def subscribe(
        self, topic: str, type: str, throttle_rate: int = 0, queue_length: int = 0
    ) -> None:
        self.subscribed[topic] = type

    def publish(self, topic: str, msg: Any, urgent: bool = False) -> None:
        self.published.append((topic, msg))

    def hold(self) -> None:
        """Nothing is held here: published is what the executive asked for."""

    def release(self) -> None:
        """Nothing was held."""

    def leave(self) -> None:
        self.left = True

    def start(self) -> None:
        self.connect()

    def connect(self, connected: bool = True) -> None:
        self._link = LinkState(connected=connected, since=time.monotonic())
        if self.on_link is not None:
            self.on_link(self._link)

    def feed(self, topic: str, msg: dict[str, Any]) -> None:
        """A message on ``topic`` from the robot."""
        value = ROS_TYPES[self.subscribed[topic]].decode(msg)
        self.on_input(topic, value, msg)

    async def wait_connected(self, timeout: float | None = None) -> bool:
        return self._link.connected

    async def flush(self, timeout: float) -> bool:
        return True

    async def close(self) -> None:
        self.closed = True


class FakeFrontend:
    """A :class:`~frog_bt.frontend.link.FrontendPort` with no wire: commands sent are kept;
    :meth:`feed` hands the executive an event."""

    def __init__(self) -> None:
        self.on_message: Any = None
        self.on_datagram: DatagramTap | None = None
        self.last_heard: float | None = None
        self.sent: list[FrontendMessage] = []
        self._stats = LinkStats()

    @property
    def stats(self) -> LinkStats:
        return self._stats

    @property
    def pending(self) -> int:
        return 0

    @property
    def oldest_pending(self) -> float | None:
        return None

    def send(self, message: FrontendMessage) -> None:
        self.sent.append(message)

    def feed(self, message: FrontendMessage, now: float) -> None:
        self.last_heard = now
        self.on_message(message)

    async def start(self) -> None:
        pass

    async def drain(self, timeout: float) -> bool:
        return True

    def close(self) -> None:
        pass

    async def wait_closed(self) -> None:
        pass
