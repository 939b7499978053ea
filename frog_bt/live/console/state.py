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
from frog_bt.i18n import Msg, say
from frog_bt.live.telemetry.site_map import poi_marks, tour_routes, zone_outlines
from frog_bt.model import keys
from frog_bt.model.help import Help
from frog_bt.model.outcomes import TourState
from frog_bt.runtime.logctx import OwnedBy
from frog_bt.runtime.phrase import doing as phrase_of
from frog_bt.runtime.phrase import of
from frog_bt.runtime.status import phase
from frog_bt.text import InertFormatter

if TYPE_CHECKING:
    from frog_bt.live.console.day import Day
    from frog_bt.model.channels import Alert
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
        self.setFormatter(InertFormatter("%(asctime)s %(message)s", "%H:%M:%S"))

    def emit(self, record: logging.LogRecord) -> None:
        try:  # staff read the message; a warning says so, the logger's name is for the team
            line = self.format(record)
            if record.levelno >= logging.WARNING:
                time, _, rest = line.partition(" ")
                line = f"{time} {record.levelname.capitalize()}: {rest}"
            self.lines.append(line)
        except Exception:  # a log line must never break the executive
            self.handleError(record)


class StopClock:
    """When the robot arrived at the current stop (the console shows the time spent there,
    not the drive to it)."""

    def __init__(self) -> None:
        self.stop: str | None = None
        self.since: float | None = None

    def seen(self, stop: str | None, now: float, arrived: bool = True) -> float | None:
        if stop != self.stop:
            self.stop, self.since = stop, None
        if stop is not None and arrived and self.since is None:
            self.since = now
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


DRIVING = ("Navigate", "GuidedDrive")


def site_map(executive: Executive) -> dict[str, Any]:
    """The static map: POIs (with the names staff know them by; functional waypoints,
    those without content or a place in the tour, left out), the tour's routes, the zones
    (metres, map frame)."""
    site = executive.site
    shown = {site.tour.dock, site.tour.recruit_at}
    for stop in site.tour.stops:
        if not stop.content:
            continue  # a functional waypoint (TEMP): the robot passes it, staff need not
        shown.add(stop.poi)
        shown.update(v.waypoint for v in site.variants.get(stop.poi, []))
    marks, named = [], set()
    for m in poi_marks(site):
        name = site.name(m.label)
        if m.label not in shown or name in named:
            continue  # a second variant of a stop is the same place for staff
        named.add(name)
        marks.append({"label": m.label, "name": name, "x": m.x, "y": m.y})
    return {
        "pois": marks,
        "routes": [{"label": r.label, "points": r.points} for r in tour_routes(site)],
        "zones": [
            {"label": z.label, "kind": z.kind, "points": z.points} for z in zone_outlines(site)
        ],
        "stops": [s.poi for s in site.tour.stops],
        "names": {s.poi: site.name(s.poi) for s in site.tour.stops},
        "dock": site.tour.dock,
        "recruit_at": site.tour.recruit_at,
        "language": site.language,
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
    site = executive.site
    path = list(running_path(core.root))
    steps = [of(node) for node in path]
    help_ = board.get(keys.HELP)
    doing = phrase_of(core)
    arrived = not any(step.kind in DRIVING for step in steps)
    book = executive.staff.book
    return {
        "phase": phase(core),
        "doing": say(doing, site.language),
        "stop": stop,
        "stop_name": site.name(stop) if stop is not None else None,
        "next_stop": following,
        "next_stop_name": site.name(following) if following is not None else None,
        "waypoint": board.get(keys.WAYPOINT) if touring else None,
        "at_stop_s": stop_clock.seen(stop, now, arrived),
        "visitor": board.get(keys.VISITOR) if touring else None,
        "introducing": doing.msgid == INTRODUCING,
        "engagement": board.get(keys.ENGAGEMENT_METER),
        "battery": diagnostics.value.battery if diagnostics is not None else None,
        "paused": bool(board.get(keys.PAUSED)),
        "in_service": board.get(keys.IN_SERVICE) is not False,
        "help": _help(help_, site.language),
        "touring": touring,
        "links": links,
        "links_for_s": {name: now - since[name][1] for name in links if name in since},
        # CONTRACT §7: the alerts raised now (a cleared one leaves the list)...
        "alerts": [_alert(a) for a in book.shown() if a.state != "cleared"],
        # ... and, for the page, the cleared ones no person has acknowledged yet (grey)
        "cleared": [_alert(a) for a in book.shown() if a.state == "cleared"],
        # acknowledged, and still true: the page says so until it is resolved
        "holding": [
            {"id": a.id, "kind": a.kind, "text": a.text, "since": a.since}
            for cid, a in sorted(book.active.items(), key=lambda item: item[1].since)
            if cid not in book.unacknowledged
        ],
        "words": {"doing": doing.wire(), "help": _help_words(help_)},
        "can": _can(board, touring, help_ is not None, executive),
        "language": site.language,
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
        "path": [node.name for node in path],
        "log": list(logs.lines),
        "time": now,
    }


INTRODUCING = "Introducing itself to a visitor"  # runtime/phrase.py's words for it


def _alert(a: Alert) -> dict[str, Any]:
    return {
        "id": a.id,
        "kind": a.kind,
        "text": a.text,
        "since": a.since,
        "state": a.state,
        "severity": a.severity,
        "answers": list(a.answers),
    }


def _help(help_: Help | None, language: str) -> dict[str, Any] | None:
    """CONTRACT §7 ``help``: what is wrong, since when, the answers a person can give (in
    the site's language)."""
    if help_ is None:
        return None
    return {
        "what": say(Msg(help_.what), language),
        "since": help_.since,
        "answers": list(help_.answers),
        "about": help_.about.value,
        "by_hand": say(Msg(help_.about.by_hand), language),
    }


def _help_words(help_: Help | None) -> dict[str, Any] | None:
    """``help``'s sentences for a page that speaks another language than the site."""
    if help_ is None:
        return None
    return {"what": Msg(help_.what).wire(), "by_hand": Msg(help_.about.by_hand).wire()}


def _can(board: Any, touring: bool, needs_help: bool, executive: Executive) -> list[str]:
    """The commands that can apply now (the page enables only their buttons; the
    executive still decides, and says why not)."""
    ending = board.get(keys.HOME) is not None or board.get(keys.ABORT_REASON) is not None
    paused = bool(board.get(keys.PAUSED))
    in_service = board.get(keys.IN_SERVICE) is not False
    can = []
    if touring and not ending and not needs_help:
        can.append("home")
        if executive.core.stops_now():  # at a stop or driving to one
            can.append("skip")
    if touring and not paused and not needs_help:
        can.append("pause")
    if paused:
        can.append("resume")
    can.append("service_off" if in_service else "service_on")
    if needs_help:
        can += ["retry", "done_by_hand"]
    return can
