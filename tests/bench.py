"""A Core driven by hand: no sockets, a ManualClock, outputs captured in lists."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import py_trees

from frog_bt.behaviours import load_tree
from frog_bt.clock import ManualClock
from frog_bt.config import Site, load_site
from frog_bt.engine.core import Core
from frog_bt.model.frontend import FrontendMessage
from frog_bt.model.ros import (
    PersonDetection,
    PersonDetections,
    Point,
    Pose,
    TrackedPeople,
    TrackedPerson,
)
from frog_bt.runtime.observer import Observers
from frog_bt.tree.loader import LoadedTree

MORNING = 1780302600.0  # 2026-06-01 10:30 Europe/Madrid
AFTERNOON = MORNING + 4 * 3600  # 14:30


def write_tree(tmp_path: Path, text: str, name: str = "t.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


class Bench:
    """A core ticked by hand; an observer Host without wire traffic or links."""

    links = None
    sim_time = False

    def __init__(
        self, tree: LoadedTree | Path | str, site: Site | None = None, start: float = MORNING
    ) -> None:
        self.site = site or load_site()
        if not isinstance(tree, LoadedTree):
            tree = load_tree(tree, self.site)
        self.clock = ManualClock(start)
        self.published: list[tuple[str, dict[str, Any]]] = []
        self.sent: list[FrontendMessage] = []
        self.observers = Observers()
        self.core = Core(
            self.site,
            tree,
            self.clock,
            lambda topic, msg, urgent: self.published.append((topic, msg)),
            lambda message: self.sent.append(message),
            emit=self.observers,
        )

    # inputs
    def ros(self, role: str, value: Any) -> None:
        self.core.on_ros(self.site.topic(role), value)

    def event(self, message: FrontendMessage) -> None:
        self.core.on_event(message)

    def pose(self, x: float, y: float) -> None:
        self.ros("pose", Pose(self.clock.now(), "map", x, y, 0.0, 1.0))

    def at(self, waypoint: str) -> None:
        """The robot's pose at ``waypoint`` (an arrival there is then believed)."""
        poi = self.site.pois[waypoint]
        self.pose(poi.x, poi.y)

    def persons(self, *persons: tuple[int, float, float, float]) -> None:
        self.ros(
            "persons",
            PersonDetections(
                self.clock.now(),
                tuple(PersonDetection(i, Point(x, y), o) for i, x, y, o in persons),
            ),
        )

    def people(self, *people: tuple[int, float, float]) -> None:
        self.ros(
            "people",
            TrackedPeople(
                self.clock.now(), tuple(TrackedPerson(i, Point(x, y)) for i, x, y in people)
            ),
        )

    # time and ticks
    def tick(self, n: int = 1) -> py_trees.common.Status:
        for _ in range(n):
            status = self.core.tick()
        return status

    def advance(self, seconds: float) -> None:
        self.clock.advance(seconds)

    def node(self, name: str) -> py_trees.behaviour.Behaviour:
        matches = [n for n in self.core.root.iterate() if n.name == name]
        assert len(matches) == 1, f"{len(matches)} nodes named {name!r}"
        return matches[0]

    # outputs
    def take_published(self) -> list[tuple[str, dict[str, Any]]]:
        out, self.published = self.published, []
        return out

    def take_sent(self) -> list[FrontendMessage]:
        out, self.sent = self.sent, []
        return out
