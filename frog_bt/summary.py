"""What happened on a tour, from the executive's own traffic (``frog-bt demo`` prints it).

:class:`TourSummary` is a set of taps for :class:`~frog_bt.executive.Taps`: it
watches the goals sent and answered, the content started, the visitors
approached and recruited.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import py_trees

from frog_bt.config import Site
from frog_bt.engagement import Decision
from frog_bt.frontend.messages import StartPoi, UserPositive
from frog_bt.messages import decode_pose
from frog_bt.topics import SUCCEEDED


@dataclass
class TourSummary:
    site: Site
    visited: list[str] = field(default_factory=list)  # waypoints arrived at, in order
    content: list[tuple[str, str, str]] = field(default_factory=list)  # (poi, waypoint, part)
    approached: list[int] = field(default_factory=list)
    recruited: list[int] = field(default_factory=list)
    decisions: list[tuple[str, Decision]] = field(default_factory=list)  # (about, decision)
    _goal: str | None = None
    _last_decision: Any = None

    def waypoint_of(self, msg: dict[str, Any]) -> str:
        pose = decode_pose(msg)
        for name, poi in self.site.pois.items():
            if (abs(poi.x - pose.x) < 1e-6 and abs(poi.y - pose.y) < 1e-6
                    and abs(poi.z - pose.qz) < 1e-6 and abs(poi.w - pose.qw) < 1e-6):
                return name
        return f"({pose.x:.1f}, {pose.y:.1f})"

    # taps: (t, channel, payload)
    def ros_out(self, t: float, topic: str, msg: Any) -> None:
        if topic == self.site.topic("goto"):
            self._goal = self.waypoint_of(msg)
        elif topic == self.site.topic("approach"):
            self._goal = None
            self.approached.append(msg["data"])

    def ros_in(self, t: float, topic: str, value: Any) -> None:
        if topic == self.site.topic("response") and value == SUCCEEDED and self._goal:
            self.visited.append(self._goal)
            self._goal = None

    def frontend_out(self, t: float, type_: str, message: Any) -> None:
        if isinstance(message, StartPoi):
            self.content.append((message.poi, message.waypoint, message.part))

    def frontend_in(self, t: float, type_: str, message: Any) -> None:
        if isinstance(message, UserPositive) and self.approached:
            self.recruited.append(self.approached[-1])

    def tick(self, core: Any) -> None:
        decision = py_trees.blackboard.Blackboard.storage.get("/engagement_decision")
        if decision is not None and decision is not self._last_decision:
            self._last_decision = decision
            self.decisions.append(decision)

    def attach(self, taps: Any) -> None:
        taps.tick.append(self.tick)
        taps.ros_out.append(self.ros_out)
        taps.ros_in.append(self.ros_in)
        taps.frontend_out.append(self.frontend_out)
        taps.frontend_in.append(self.frontend_in)

    def lines(self) -> list[str]:
        played = ", ".join(f"{poi} {part}" + (f" ({wp})" if wp != poi else "")
                           for poi, wp, part in self.content) or "none"
        return [
            f"route:     {' -> '.join(self.visited) or 'nowhere'}",
            f"content:   {played}",
            f"visitors:  approached {self.approached or 'none'}, "
            f"recruited {self.recruited or 'none'}",
            *(f"{'engaged?' if i == 0 else '':<10} {about}: {d.describe()}"
              for i, (about, d) in enumerate(self.decisions)),
        ]
