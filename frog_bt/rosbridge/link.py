"""What the program can see of the rosbridge link, with no websockets import.

:class:`LinkState` is the value the client hands to its ``on_link`` callback
and exposes as ``client.link``; :class:`ClientStats` are its counters. Both are
plain data so that the tree, telemetry and tests can use them without pulling in
the network adapter.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field


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
