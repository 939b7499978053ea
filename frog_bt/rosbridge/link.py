"""What the program can see of the rosbridge link, with no websockets import.

:class:`LinkState` is the value the client hands to its ``on_link`` callback
and exposes as ``client.link``; :class:`ClientStats` are its counters. Both are
plain data so that the tree, telemetry and tests can use them without pulling in
the network adapter. :class:`RobotLink` is what the executive needs of the link
(the client, or a fake handed in instead).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol


@dataclass(frozen=True, slots=True)
class LinkState:
    """The link as of its last change.

    ``connected`` is true between a completed WebSocket handshake and the loss
    of that connection. ``since`` is ``time.monotonic()`` at the last change of
    ``connected``. ``reconnects`` counts successful connections after the
    first. ``last_error`` says why the link is down or why the latest attempt
    to connect failed; it is ``None`` while connected and after a deliberate
    ``close()``.

    While down: ``attempt`` is the number of the next attempt since the last
    connection that stayed up (1 after a first failure), ``retry_at`` the
    ``time.monotonic()`` it is due, and ``refused`` whether the latest
    connection was closed by the server right after it opened while an auth
    secret was set: how a rosbridge server refuses an ``auth`` (it sends no
    status frame, and need not use close code 1008).
    """

    connected: bool
    since: float
    reconnects: int = 0
    last_error: str | None = None
    attempt: int = 0
    retry_at: float | None = None
    refused: bool = False

    @property
    def retry_in(self) -> float | None:
        """Seconds until the next attempt (None while connected or closed)."""
        return None if self.retry_at is None else max(0.0, self.retry_at - time.monotonic())


@dataclass(slots=True)
class ClientStats:
    """Counters of one client, for the status display and for tests.

    * ``received``: inbound frames read off the socket, good or bad.
    * ``malformed``: inbound frames or messages that failed to decode;
      ``malformed_by_topic`` splits them by topic (``"<frame>"`` when the frame
      itself was unreadable, so no topic is known).
    * ``dropped``: publishes dropped (oldest first) from the full queue while
      the link was down.
    * ``ignored``: well-formed frames not meant for the program: unknown ops,
      publishes on topics it did not subscribe to.
    * ``reconnects``: successful connections after the first.
    * ``sent``: frames written to the socket.
    * ``connect_failures``: attempts to connect that failed.
    """

    received: int = 0
    malformed: int = 0
    ignored: int = 0
    dropped: int = 0
    reconnects: int = 0
    sent: int = 0
    connect_failures: int = 0
    malformed_by_topic: dict[str, int] = field(default_factory=dict)


class RobotLink(Protocol):
    """What the executive needs of its link to the robot, handed to it ready-made:
    :class:`~frog_bt.rosbridge.client.RosbridgeClient` (over a socket, or over a
    :class:`~frog_bt.rosbridge.memory.MemoryWire` in tests), or any fake with this shape.

    The executive sets ``on_input(topic, value, msg)`` (every message on a subscribed
    topic; ``value`` None when it did not decode) and ``on_link(state)`` (each change of
    :attr:`link`) before it calls :meth:`start`. The calls that send never block.
    """

    url: str
    on_input: Callable[[str, object, Any], None] | None
    on_link: Callable[[LinkState], None] | None

    @property
    def link(self) -> LinkState: ...
    @property
    def stats(self) -> ClientStats: ...

    def advertise(self, topic: str, type: str) -> None: ...
    def subscribe(
        self, topic: str, type: str, throttle_rate: int = 0, queue_length: int = 0
    ) -> None: ...
    def publish(self, topic: str, msg: Any, urgent: bool = False) -> None: ...
    def hold(self) -> None:
        """Keep what is published until :meth:`release` (or an ``urgent`` publish)."""

    def release(self) -> None:
        """Send what :meth:`hold` kept, in order."""

    def leave(self) -> None:
        """Unsubscribe and unadvertise everything (while connected)."""

    def start(self) -> object:
        """Connect (and reconnect for ever) in a task of its own."""

    async def wait_connected(self, timeout: float | None = None) -> bool: ...
    async def flush(self, timeout: float) -> bool: ...
    async def close(self) -> None: ...
