"""What happened on a tour, from the executive's own traffic (``frog-bt demo`` prints it).

:class:`TourSummary` is an :class:`~frog_bt.runtime.observer.Observer`: it watches
the goals sent and answered, the content started, the visitors approached and
recruited, and reads the incidents from the one tally
(:class:`~frog_bt.engine.tally.Tally`). Its tours, their stops (reached, played,
skipped and why) and its verdict are the one count of tours'
(:class:`~frog_bt.model.ledger.TourLedger`; a tour the executive resumed is carried on
from its checkpoint, :mod:`frog_bt.runtime.resuming`), the same fold the console and the
report read.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from frog_bt.config import Site
from frog_bt.engine.context import Incident
from frog_bt.maths.engagement import Decision
from frog_bt.model import keys
from frog_bt.model.events import (
    Doubted,
    Event,
    FrontendIn,
    FrontendOut,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.frontend import FrontendMessage, StartPoi, UserPositive
from frog_bt.model.outcomes import IncidentKind
from frog_bt.model.ros import POSE
from frog_bt.model.tours import TourRow
from frog_bt.model.wire import SUCCEEDED
from frog_bt.runtime.observer import Host
from frog_bt.runtime.resuming import ResumingLedger

if TYPE_CHECKING:
    from frog_bt.engine.core import Core


@dataclass
class TourSummary:
    site: Site
    visited: list[str] = field(default_factory=list)  # waypoints arrived at, in order
    content: list[tuple[str, str, str]] = field(default_factory=list)  # (poi, waypoint, part)
    approached: list[int] = field(default_factory=list)
    recruited: list[int] = field(default_factory=list)
    decisions: list[tuple[str, Decision]] = field(default_factory=list)  # (about, decision)
    incidents: list[Incident] = field(default_factory=list)
    doubted: list[str] = field(default_factory=list)  # robot answers not believed: why
    resumed: str | None = None
    _goal: str | None = None
    _last_decision: Any = None
    _seen_incidents: int = 0
    _host: Host | None = None
    ledger: ResumingLedger | None = None  # the one count of tours, the site's plan

    def __post_init__(self) -> None:
        self.ledger = ResumingLedger(self.site.tour_plan())

    def waypoint_of(self, msg: dict[str, Any]) -> str:
        return self.site.waypoint_of(POSE.convert(msg))

    def on_event(self, event: Event) -> None:
        assert self.ledger is not None
        self.ledger.on_event(event)
        match event:
            case RobotInput():
                self._ros_in(event)
            case RobotCommand():
                self._ros_out(event)
            case FrontendOut(message=message):
                self._frontend_out(message)
            case FrontendIn(message=message):
                self._frontend_in(message)
            case Ticked() if self._host is not None:
                self._tick(self._host.core)
            case Doubted(why=why):
                self.doubted.append(why)

    def _ros_out(self, out: RobotCommand) -> None:
        if out.role == "goto" and out.goal is not None:
            self._goal = out.goal.target  # the waypoint, as the tree named it
        elif out.role == "approach" and isinstance(out.value, int):
            self._goal = None
            self.approached.append(out.value)

    def _ros_in(self, event: RobotInput) -> None:
        if event.topic == self.site.topic("response") and event.value == SUCCEEDED and self._goal:
            self.visited.append(self._goal)
            self._goal = None

    def _frontend_out(self, message: FrontendMessage) -> None:
        if isinstance(message, StartPoi):
            self.content.append((message.poi, message.waypoint, message.part))

    def _frontend_in(self, message: FrontendMessage) -> None:
        if isinstance(message, UserPositive) and self.approached:
            self.recruited.append(self.approached[-1])

    def _tick(self, core: Core) -> None:
        board = core.board
        decision = board.get(keys.ENGAGEMENT_DECISION)
        if decision is not None and decision is not self._last_decision:
            self._last_decision = decision
            self.decisions.append(decision)
        journal = core.journal
        self.incidents.extend(journal.incidents_since(self._seen_incidents))
        self._seen_incidents = journal.incident_total
        resumed = board.get(keys.RESUMED)
        if resumed and self.resumed is None:
            self.resumed = resumed

    @property
    def tours(self) -> list[str]:
        """The tours over: "ended" / "aborted: reason", in order."""
        assert self.ledger is not None
        return [
            r.ended + (f": {r.reason}" if r.reason else "") for r in self.ledger.tours if r.ended
        ]

    @property
    def latest(self) -> TourRow | None:
        assert self.ledger is not None
        return self.ledger.latest

    @property
    def skipped(self) -> list[str]:
        """The content stops the latest tour left (skipped by the operator, given up, or
        their visitor lost) and did not reach after, in tour order."""
        row = self.latest
        assert self.ledger is not None
        return row.left(self.ledger.plan.content) if row else []

    def stops(self) -> str:
        """The latest tour's stops: ``4 of 6 reached, 4 played; skipped POI3 (operator)``."""
        row = self.latest
        assert self.ledger is not None
        order = self.ledger.plan.content
        if row is None:
            return "none"
        reached = len({p for p in row.reached if p in order})
        played = len({p for p in row.played if p in order})
        text = f"{reached} of {len(order)} reached, {played} played"
        skips = row.skips(order)
        if skips:
            text += "; skipped " + ", ".join(f"{poi} ({why})" for poi, why in skips)
        return text

    def attach(self, host: Host) -> None:
        self._host = host
        assert self.ledger is not None
        self.ledger.attach(host)

    def close(self) -> None:
        """Nothing to finish: the summary is read from its fields."""

    # ------------------------------------------------------------ verdict

    @property
    def complete(self) -> bool:
        """The latest tour ended docked with every stop visited."""
        return bool(self.tours) and self.tours[-1] == "ended" and not self.skipped

    def verdict(self) -> str:
        if not self.tours:
            return "no tour ended"
        last = self.tours[-1]
        if last != "ended":
            return f"tour {last}"
        if self.skipped:
            return f"tour ended docked, but {_words(self.skipped)} skipped"
        return "tour ended docked, every stop visited"

    def lines(self, frontend: Any = None) -> list[str]:
        """The summary, one line each; ``frontend`` (the link's stats) adds its restarts
        and the commands it never acked."""
        played = (
            ", ".join(
                f"{poi} {part}" + (f" ({wp})" if wp != poi else "")
                for poi, wp, part in self.content
            )
            or "none"
        )
        out = [
            f"route:     {' -> '.join(self.visited) or 'nowhere'}",
            f"content:   {played}",
            f"stops:     {self.stops()}",
            f"visitors:  {_visitors(self.approached, self.recruited)}",
            *(
                f"{'engaged?' if i == 0 else '':<10} {about}: {d.describe()}"
                for i, (about, d) in enumerate(self.decisions)
            ),
        ]
        if self.resumed:
            out.append(f"resumed:   {self.resumed}")
        # by kind; a link's own count replaces its kind's (IncidentKind is a StrEnum)
        counts = Counter[str](i.kind for i in self.incidents if i.kind is not IncidentKind.RESUMED)
        if frontend is not None and frontend.peer_restarts:
            counts["front end restarted"] = frontend.peer_restarts
        if frontend is not None and frontend.unacked:
            counts["front-end commands never acked"] = frontend.unacked
        if counts:
            out.append(
                "problems:  "
                + "; ".join(f"{kind} ({n})" if n > 1 else kind for kind, n in counts.items())
            )
            out += [
                f"{'':<10} {i.text}" for i in self.incidents[-MAX_LISTED:] if i.kind != "resumed"
            ]
        if self.doubted:
            n = len(self.doubted)
            out.append(f"not believed: {n} robot answer{'s' if n > 1 else ''} (not acted on)")
            out += [f"{'':<10} {why}" for why in self.doubted[-MAX_LISTED:]]
        out.append(f"outcome:   {self.verdict()}")
        return out


MAX_LISTED = 12  # incidents listed one per line (the counts cover all of them)


def _words(items: list[Any]) -> str:
    words = [str(i) for i in items]
    if len(words) <= 1:
        return "".join(words)
    return ", ".join(words[:-1]) + " and " + words[-1]


def _visitors(approached: list[int], recruited: list[int]) -> str:
    if not approached:
        return "nobody approached"
    times = Counter(approached)
    people = [f"{pid}" + (f" ({n} times)" if n > 1 else "") for pid, n in times.items()]
    text = f"approached {_words(people)}"
    return text + (
        f"; recruited {_words(list(dict.fromkeys(recruited)))}"
        if recruited
        else "; nobody recruited"
    )
