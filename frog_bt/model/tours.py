"""A tour's row, as the one count of tours (:mod:`frog_bt.model.ledger`) keeps it: the
tour's stop visits (:class:`StopVisit`, each with its :class:`Fate`), its staff commands,
help requests, goals, visitors and outcome (:class:`TourRow`), what the count needs of the
site (:class:`TourPlan`), and which content stops a tour did not reach, and why
(:func:`skips`, :class:`SkipWhy`). Values only: the fold that fills them is
:class:`~frog_bt.model.ledger.TourLedger`.

What a visit of a stop comes to (:attr:`StopVisit.fate`), exactly one of:

* **skipped** (:class:`SkipWhy`): left before it was played. ``operator``: a ``skip``
  accepted while the robot drove there or played its content; ``navigation failed``: the
  robot gave the stop up (its goals failed, and the tour moved on without an arrival);
  ``visitor lost``: the tour went back to recruit (an approach or an invitation) before
  the stop was played. A skipped visit is neither reached nor played.
* **played**: reached, and the front end said its part a was done (``content_done``).
* **reached**: the robot arrived and the executive believed it (the goal there answered
  ``succeeded`` and no :class:`~frog_bt.model.events.Doubted` withdrew it, or its content
  started), not skipped, and not (yet) played.
* **under way**: none of those (driving there, or the tour ended on the way).

So played ⊆ reached, and a skipped visit is in neither. A tour's row lists the stops it
reached (each visit: a stop visited again for a new visitor is counted again) and the
content stops it skipped (:func:`skips`): each stop once, and never one it reached.
"""

from __future__ import annotations

import copy
import enum
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

import msgspec

from frog_bt.model.outcomes import TourState
from frog_bt.model.ros import Pose

__all__ = [
    "LEFT",
    "Fate",
    "SkipWhy",
    "StaffCommand",
    "StopVisit",
    "TourPlan",
    "TourRow",
    "skips",
]


class SkipWhy(enum.StrEnum):
    """Why a stop was not reached (the report's words)."""

    OPERATOR = "operator"
    NAVIGATION = "navigation failed"
    VISITOR_LOST = "visitor lost"
    NOT_RECORDED = "not recorded (restart)"  # offline: a gap a restart left in the files
    NOT_VISITED = "not visited"


LEFT = (SkipWhy.OPERATOR, SkipWhy.NAVIGATION, SkipWhy.VISITOR_LOST)


class Fate(enum.StrEnum):
    UNDER_WAY = "under way"
    REACHED = "reached"
    PLAYED = "played"
    SKIPPED = "skipped"


@dataclass(frozen=True)
class TourPlan:
    """What the fold needs of the site: the tour's stops in order (``content``: those with
    content, the report's order), each waypoint's stop (time-of-day variants too), the
    input topics by role, the face-stream stops and the engagement rule's ``near`` and
    ``edge``; ``waypoint_of`` names a goal's pose when the event carries no goal."""

    stops: tuple[str, ...] = ()
    content: tuple[str, ...] = ()
    waypoints: Mapping[str, str] = field(default_factory=dict)
    topics: Mapping[str, str] = field(default_factory=dict)  # role -> topic
    face_stops: frozenset[str] = frozenset()
    near: float = 2.0
    edge: float = 0.15
    waypoint_of: Callable[[Pose], str] | None = None


@dataclass
class StopVisit:
    """One visit of a stop: from the first goal there (or its content's start, when the
    goal is not in what was folded) to the next stop, a recruitment or the tour's end."""

    poi: str
    t: float = 0.0  # opened
    waypoint: str = ""  # the waypoint driven to or played (a time-of-day variant)
    parts: str = ""  # content parts started: "a", "ab"
    start: float | None = None  # part a started
    end: float | None = None  # finish_poi
    a_end: float | None = None  # the front end said part a was done
    arrived: bool = False  # arrival believed (see the module's definitions)
    skipped: SkipWhy | None = None
    goals_failed: int = 0
    face_stream: bool = False
    samples: int = 0  # face samples stored (near and facing) to part a's end
    edge_engaged: int = 0
    edge_total: int = 0
    before_restart: float = 0.0  # seconds of this visit before a restart cut it (joined)
    closed: bool = False

    @property
    def fate(self) -> Fate:
        if self.skipped is not None:
            return Fate.SKIPPED
        if self.arrived and self.a_end is not None:
            return Fate.PLAYED
        return Fate.REACHED if self.arrived else Fate.UNDER_WAY

    @property
    def reached(self) -> bool:
        return self.fate in (Fate.REACHED, Fate.PLAYED)

    @property
    def played(self) -> bool:
        return self.fate is Fate.PLAYED

    @property
    def seconds(self) -> float | None:
        """Time at the stop: part a to ``finish_poi`` (and the time before a restart)."""
        if self.start is None or self.end is None:
            return None
        return self.end - self.start + self.before_restart

    @property
    def decision(self) -> str:
        """What the engagement gate did: ``b`` (part b played), ``a only`` (part a played
        to its end, no part b) or ``none`` (part a was cut before the gate)."""
        if "b" in self.parts:
            return "b"
        return "a only" if self.a_end is not None else "none"

    def carried_on(self, later: StopVisit) -> StopVisit:
        """This visit, cut by a restart, and ``later``, the resumed executive's visit of
        the same stop: one visit (parts joined, the time before the restart kept)."""
        return replace(
            later,
            t=self.t,
            parts="".join(dict.fromkeys(self.parts + later.parts)),
            arrived=self.arrived or later.arrived,
            skipped=later.skipped or self.skipped,
            goals_failed=self.goals_failed + later.goals_failed,
            before_restart=self.seconds if self.seconds is not None else self.before_restart,
        )


@dataclass(frozen=True)
class StaffCommand:
    """An operator command during a tour, and its answer."""

    t: float
    command: str
    ok: bool
    by: str = ""
    text: str = ""


@dataclass
class TourRow:
    """One tour, or the part of one that the fold saw."""

    started: float | None = None  # `tour started` (None: the fold began inside it)
    t0: float = 0.0  # first event of the row
    t1: float = 0.0  # last event of the row
    ended: str = ""  # "ended" | "aborted" | "" (not over in what was folded)
    reason: str = ""
    distance: float = 0.0  # metres driven
    stops: list[StopVisit] = field(default_factory=list)
    goals: int = 0  # goto goals sent
    failed_goals: list[str] = field(default_factory=list)  # waypoints of goals answered 3/4
    nav_retries: int = 0  # goals sent again to the waypoint whose goal had just failed
    dock_retries: int = 0  # dock/undock sent again after /docking/state failed
    approaches: int = 0
    approaches_ok: int = 0
    approaches_rejected: int = 0
    approached: list[int] = field(default_factory=list)  # person ids, in order
    visitors: list[int] = field(default_factory=list)  # the approached who said yes
    invitations: int = 0
    accepted: int = 0
    declined: int = 0
    faults: list[tuple[str, str]] = field(default_factory=list)  # (name, message), once each
    help: list[str] = field(default_factory=list)  # alerts raised asking a person (kinds)
    commands: list[StaffCommand] = field(default_factory=list)
    doubted: int = 0  # robot answers not believed

    def of_a_tour(self) -> bool:
        """Something only a tour does happened in it."""
        return bool(self.stops or self.invitations or self.approaches or self.goals or self.ended)

    @property
    def reached(self) -> list[str]:
        """The stops reached, in order (a stop visited again is listed again)."""
        return [v.poi for v in self.stops if v.reached]

    @property
    def played(self) -> list[str]:
        """The stops whose content played to its end, in order."""
        return [v.poi for v in self.stops if v.played]

    @property
    def operator_skips(self) -> list[str]:
        return [v.poi for v in self.stops if v.skipped is SkipWhy.OPERATOR]

    def skips(self, order: Iterable[str]) -> list[tuple[str, SkipWhy]]:
        """The content stops of ``order`` this tour did not reach, and why (:func:`skips`)."""
        return skips(self.stops, list(order), self.ended)

    def carried_on(self, later: TourRow) -> TourRow:
        """This row, kept by a checkpoint (what the tour did before a restart), and
        ``later``, what the resumed executive saw of the same tour: one row. Its start is
        this row's, its end ``later``'s; lists are joined, counts added, a fault listed
        once. A visit under way when the checkpoint was written is left out: the resumed
        executive drives there again (as the report joins a visit a restart cut)."""
        kept = copy.deepcopy(self)
        while kept.stops and kept.stops[-1].fate is Fate.UNDER_WAY:
            kept.stops.pop()
        for visit in kept.stops:
            visit.closed = True
        joined: dict[str, Any] = {}
        for f in fields(TourRow):
            before, after = getattr(kept, f.name), getattr(later, f.name)
            if f.name in ("started", "t0"):
                joined[f.name] = before
            elif f.name in ("t1", "ended", "reason"):
                joined[f.name] = after
            elif f.name == "faults":
                joined[f.name] = list(dict.fromkeys(before + after))
            else:  # a list or a count
                joined[f.name] = before + after
        return replace(later, **joined)

    def to_json(self) -> dict[str, Any]:
        """The row as JSON values (a checkpoint keeps it: :meth:`of_json`)."""
        return msgspec.to_builtins(self)  # type: ignore[no-any-return]

    @classmethod
    def of_json(cls, data: object) -> TourRow | None:
        """The row :meth:`to_json` wrote; None when ``data`` is not one."""
        try:
            return msgspec.convert(data, TourRow)
        except msgspec.ValidationError:
            return None

    def left(self, order: Iterable[str]) -> list[str]:
        """The stops of :meth:`skips` that were left (by the operator, given up, or their
        visitor lost), not merely never visited: what staff call "skipped"."""
        return [poi for poi, why in self.skips(order) if why in LEFT]


def skips(
    visits: list[StopVisit],
    order: list[str],
    ended: str,
    lost: frozenset[str] = frozenset(),
) -> list[tuple[str, SkipWhy]]:
    """Each content stop of ``order`` that no visit reached, and why: the last skip of it,
    else ``not recorded (restart)`` for one in ``lost`` (offline), else ``not visited``.
    For a tour that did not end, only up to the last stop it reached or skipped."""
    reached = {v.poi for v in visits if v.reached}
    why: dict[str, SkipWhy] = {}
    for v in visits:
        if v.skipped is not None:
            why[v.poi] = v.skipped
    decided = reached | set(why)
    reach = (
        len(order)
        if ended == TourState.ENDED
        else max((order.index(p) + 1 for p in decided if p in order), default=0)
    )
    out = []
    for poi in order[:reach]:
        if poi in reached:
            continue
        default = SkipWhy.NOT_RECORDED if poi in lost else SkipWhy.NOT_VISITED
        out.append((poi, why.get(poi, default)))
    return out
