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

from dataclasses import dataclass
from typing import Any

SILENT_AFTER = 2.0  # project-clock seconds without a datagram while commands wait


@dataclass(frozen=True, slots=True)
class Links:
    rosbridge: str
    frontend: str
    clock: str

    def items(self) -> tuple[tuple[str, str], ...]:
        return (("rosbridge", self.rosbridge), ("frontend", self.frontend),
                ("clock", self.clock))

    def text(self) -> str:
        """``rosbridge connected, front end silent, clock /clock``."""
        return (f"rosbridge {self.rosbridge}, front end {self.frontend}, "
                f"clock {self.clock}")


def changed(seen: dict[str, str], links: Links) -> list[tuple[str, str]]:
    """The (link, state) pairs of ``links`` that differ from ``seen``, which takes them."""
    out = [(name, state) for name, state in links.items() if seen.get(name) != state]
    seen.update(out)
    return out


def rosbridge_state(link: Any, was_connected: bool) -> str:
    if link.connected:
        return "connected"
    if was_connected and link.last_error is None:
        return "closed"  # by the executive, on its way out
    return "reconnecting" if was_connected else "connecting"


def frontend_state(oldest_pending: float | None, last_heard: float | None, now: float) -> str:
    """``silent`` when a command has waited more than :data:`SILENT_AFTER` for its ack
    and nothing came from the front end since it was sent."""
    if (oldest_pending is not None and now - oldest_pending > SILENT_AFTER
            and (last_heard is None or last_heard < oldest_pending)):
        return "silent"
    return "acking" if last_heard is not None else "not heard"


def clock_state(sim_time: bool, ready: bool) -> str:
    if not sim_time:
        return "wall"
    return "/clock" if ready else "waiting for /clock"


def states(executive: Any) -> tuple[str, str, str]:
    """(rosbridge, front end, clock): cheap enough for every tick."""
    clock = executive.clock
    link = executive.link
    ready = bool(clock.ready)
    return (rosbridge_state(executive.client.link, executive.was_connected),
            frontend_state(link.oldest_pending, link.last_heard, clock.now() if ready else 0.0),
            clock_state(executive.sim_time, ready))

