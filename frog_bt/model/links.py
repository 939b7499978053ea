"""The state of each link, for the operator: rosbridge, front end, clock.

:func:`states` reads them off the executive (no I/O, cheap enough for every tick): rosbridge
``connected`` / ``reconnecting`` / ``connecting`` (never connected yet) /
``closed``; the front end ``acking`` (it answers), ``silent`` (a command has
waited :data:`SILENT_AFTER` seconds for its ack and nothing has come from the
front end since it was sent) or ``not heard`` (nothing from it yet); the clock
``wall``, ``/clock`` or ``waiting for /clock``. The executive calls its
``wire.links`` taps with each change (status line, rerun lanes).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any

SILENT_AFTER = 2.0  # project-clock seconds without a datagram while commands wait


class Health(enum.Enum):
    """How a link state looks to the operator (the colour of its lane)."""

    OK = "ok"
    WAIT = "wait"
    BAD = "bad"
    OFF = "off"


class LinkStatus(enum.StrEnum):
    """The state of one link, in the words the status line, the log and the console use."""

    CONNECTED = "connected"
    CONNECTING = "connecting"  # never connected yet
    RECONNECTING = "reconnecting"
    CLOSED = "closed"  # by the executive, on its way out
    ACKING = "acking"
    NOT_HEARD = "not heard"
    SILENT = "silent"
    WALL = "wall"
    SIM = "/clock"
    WAITING = "waiting for /clock"

    @property
    def health(self) -> Health:
        return _HEALTH[self]


_HEALTH = {
    LinkStatus.CONNECTED: Health.OK,
    LinkStatus.ACKING: Health.OK,
    LinkStatus.WALL: Health.OK,
    LinkStatus.SIM: Health.OK,
    LinkStatus.CONNECTING: Health.WAIT,
    LinkStatus.RECONNECTING: Health.WAIT,
    LinkStatus.NOT_HEARD: Health.WAIT,
    LinkStatus.SILENT: Health.BAD,
    LinkStatus.WAITING: Health.BAD,
    LinkStatus.CLOSED: Health.OFF,
}


@dataclass(frozen=True, slots=True)
class Links:
    rosbridge: LinkStatus
    frontend: LinkStatus
    clock: LinkStatus

    def items(self) -> tuple[tuple[str, LinkStatus], ...]:
        return (("rosbridge", self.rosbridge), ("frontend", self.frontend), ("clock", self.clock))

    def text(self) -> str:
        """``rosbridge connected, front end silent, clock /clock``."""
        return f"rosbridge {self.rosbridge}, front end {self.frontend}, clock {self.clock}"


def changed(seen: dict[str, LinkStatus], links: Links) -> list[tuple[str, LinkStatus]]:
    """The (link, state) pairs of ``links`` that differ from ``seen``, which takes them."""
    out = [(name, state) for name, state in links.items() if seen.get(name) is not state]
    seen.update(out)
    return out


def rosbridge_state(link: Any, was_connected: bool) -> LinkStatus:
    if link.connected:
        return LinkStatus.CONNECTED
    if was_connected and link.last_error is None:
        return LinkStatus.CLOSED
    return LinkStatus.RECONNECTING if was_connected else LinkStatus.CONNECTING


def frontend_state(
    oldest_pending: float | None, last_heard: float | None, now: float
) -> LinkStatus:
    """``silent`` when a command has waited more than :data:`SILENT_AFTER` for its ack
    and nothing came from the front end since it was sent."""
    if (
        oldest_pending is not None
        and now - oldest_pending > SILENT_AFTER
        and (last_heard is None or last_heard < oldest_pending)
    ):
        return LinkStatus.SILENT
    return LinkStatus.ACKING if last_heard is not None else LinkStatus.NOT_HEARD


def clock_state(sim_time: bool, ready: bool) -> LinkStatus:
    if not sim_time:
        return LinkStatus.WALL
    return LinkStatus.SIM if ready else LinkStatus.WAITING


def states(executive: Any) -> tuple[LinkStatus, LinkStatus, LinkStatus]:
    """(rosbridge, front end, clock): cheap enough for every tick."""
    clock = executive.clock
    link = executive.link
    ready = bool(clock.ready)
    return (
        rosbridge_state(executive.client.link, executive.was_connected),
        frontend_state(link.oldest_pending, link.last_heard, clock.now() if ready else 0.0),
        clock_state(executive.sim_time, ready),
    )
