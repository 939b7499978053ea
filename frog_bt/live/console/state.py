"""What the console shows, as JSON: the tour now, the links, the map's moving parts, the
running path, the day so far, the alerts and the latest log lines (``GET /api/state``;
CONTRACT §7 names the fields outside tools rely on), the site's static map
(``GET /api/site``) and the whole tree with each node's status (``GET /api/tree``).

Built from what the executive already knows, read between ticks; nothing here changes
anything.
"""

from __future__ import annotations

import logging
from collections import deque
from typing import TYPE_CHECKING, Any

import py_trees

from frog_bt.engine.walk import children, running_path
from frog_bt.live.telemetry.site_map import poi_marks, tour_routes, zone_outlines
from frog_bt.model import keys
from frog_bt.model.help import Help
from frog_bt.model.outcomes import TourState
from frog_bt.runtime.logctx import OwnedBy
from frog_bt.runtime.status import phase

if TYPE_CHECKING:
    from frog_bt.live.console.day import Day
    from frog_bt.runtime.executive import Executive

Behaviour = py_trees.behaviour.Behaviour
RUNNING = py_trees.common.Status.RUNNING
LOG_LINES = 50


class LogLines(logging.Handler):
    """The latest log lines of ``owner`` (an executive), formatted as the log writes them.

    One handler per console; a record is ``owner``'s when it was logged in the context
    the executive marked as its own (:mod:`frog_bt.runtime.logctx`), so another executive
    in the same process, and the command line around them, do not show here."""

    def __init__(self, owner: object, size: int = LOG_LINES) -> None:
        super().__init__(logging.INFO)
        self.lines: deque[str] = deque(maxlen=size)
        self.addFilter(OwnedBy(owner))
        self.setFormatter(
            logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s", "%H:%M:%S")
        )

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.lines.append(self.format(record))
        except Exception:  # a log line must never break the executive
            self.handleError(record)


class StopClock:
    """When the current stop began (the console shows the time spent there)."""

    def __init__(self) -> None:
        self.stop: str | None = None
        self.since: float | None = None

    def seen(self, stop: str | None, now: float) -> float | None:
        if stop != self.stop:
            self.stop, self.since = stop, now if stop is not None else None
        return None if self.since is None else now - self.since


def running_names(root: Behaviour) -> list[str]:
    """The names from the root down the running children (what the robot is doing)."""
    return [node.name for node in running_path(root)]


def tree(node: Behaviour) -> dict[str, Any]:
    return {
        "name": node.name,
        "type": type(node).__name__,
        "status": node.status.value,
        "children": [tree(c) for c in children(node)],
    }


def site_map(executive: Executive) -> dict[str, Any]:
    """The static map: POIs, the tour's routes, the zones (metres, map frame)."""
    site = executive.site
    return {
        "pois": [{"label": m.label, "x": m.x, "y": m.y} for m in poi_marks(site)],
        "routes": [{"label": r.label, "points": r.points} for r in tour_routes(site)],
        "zones": [
            {"label": z.label, "kind": z.kind, "points": z.points} for z in zone_outlines(site)
        ],
        "stops": [s.poi for s in site.tour.stops],
        "dock": site.tour.dock,
    }


def state(executive: Executive, day: Day, logs: LogLines, stop_clock: StopClock) -> dict[str, Any]:
    """The state the console page and outside tools read (CONTRACT §7 and more)."""
    core = executive.core
    board = core.board
    now = core.clock.now() if core.clock.ready else 0.0
    touring = board.get(keys.TOUR_STATE) is TourState.STARTED
    stop = board.get(keys.TARGET) if touring else None
    stops = [s.poi for s in executive.site.tour.stops]
    following = stops[stops.index(stop) + 1] if stop in stops[:-1] else None
    diagnostics = board.get(keys.DIAGNOSTICS)
    pose = board.get(keys.POSE)
    people = board.get(keys.PEOPLE)
    links = {name: status.value for name, status in executive.links.items()}
    since = executive.staff.link_since
    return {
        "phase": phase(core),
        "stop": stop,
        "next_stop": following,
        "waypoint": board.get(keys.WAYPOINT) if touring else None,
        "at_stop_s": stop_clock.seen(stop, now),
        "visitor": board.get(keys.VISITOR) if touring else None,
        "engagement": board.get(keys.ENGAGEMENT_METER),
        "battery": diagnostics.value.battery if diagnostics is not None else None,
        "paused": bool(board.get(keys.PAUSED)),
        "in_service": board.get(keys.IN_SERVICE) is not False,
        "help": _help(board.get(keys.HELP)),
        "touring": touring,
        "links": links,
        "links_for_s": {name: now - since[name][1] for name in links if name in since},
        "alerts": [
            {
                "id": a.id,
                "kind": a.kind,
                "text": a.text,
                "since": a.since,
                "state": a.state,
                "severity": a.severity,
                "answers": list(a.answers),
            }
            for a in executive.staff.book.shown()
        ],
        "tours": {"started": day.started, "completed": day.completed, "aborted": day.aborted},
        "day": {"visitors": day.visitors, "skipped": day.skipped, "last": list(day.last)},
        "robot": (
            {"x": pose.value.x, "y": pose.value.y, "yaw": pose.value.yaw}
            if pose is not None
            else None
        ),
        "people": (
            [[p.position.x, p.position.y] for p in people.value.people]
            if people is not None
            else []
        ),
        "path": running_names(core.root),
        "log": list(logs.lines),
        "time": now,
    }


def _help(help_: Help | None) -> dict[str, Any] | None:
    """CONTRACT §7 ``help``: what is wrong, since when, the answers a person can give."""
    if help_ is None:
        return None
    return {
        "what": help_.what,
        "since": help_.since,
        "answers": list(help_.answers),
        "about": help_.about.value,
        "by_hand": help_.about.by_hand,
    }
