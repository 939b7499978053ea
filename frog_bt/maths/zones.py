"""Zones of the map (circles and polygons, map frame) with hysteresis, sans-I/O.

A robot is *in* a zone once it is inside it, and stays in it until it is more
than ``hysteresis`` metres outside, so that a robot standing on a border does
not flap between two volumes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

Point = tuple[float, float]


def _segment_distance(p: Point, a: Point, b: Point) -> float:
    (px, py), (ax, ay), (bx, by) = p, a, b
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    u = 0.0 if length2 == 0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / length2))
    return math.hypot(px - (ax + u * dx), py - (ay + u * dy))


def point_in_polygon(p: Point, polygon: Sequence[Point]) -> bool:
    x, y = p
    inside = False
    n = len(polygon)
    for i in range(n):
        (x1, y1), (x2, y2) = polygon[i], polygon[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


@dataclass(frozen=True, slots=True)
class Shape:
    """A circle (``center``, ``radius``) or a polygon (``points``)."""

    center: Point | None = None
    radius: float = 0.0
    points: tuple[Point, ...] = ()

    def outside_by(self, p: Point) -> float:
        """How far outside ``p`` is (0 or less when inside)."""
        if self.center is not None:
            return math.hypot(p[0] - self.center[0], p[1] - self.center[1]) - self.radius
        if point_in_polygon(p, self.points):
            return 0.0
        n = len(self.points)
        return min(_segment_distance(p, self.points[i], self.points[(i + 1) % n]) for i in range(n))

    def contains(self, p: Point) -> bool:
        return self.outside_by(p) <= 0.0


class Membership:
    """Which of several zones the robot is in, with hysteresis; the first listed wins."""

    def __init__(self, shapes: Sequence[Shape], hysteresis: float) -> None:
        self.shapes = list(shapes)
        self.hysteresis = hysteresis
        self.current: int | None = None

    def update(self, p: Point) -> int | None:
        """The zone index the robot is in now (None: none of them)."""
        if self.current is not None and self.shapes[self.current].outside_by(p) <= self.hysteresis:
            # still in (or within the hysteresis band of) the current zone; an earlier zone
            # that the robot is fully inside takes over
            for i in range(self.current):
                if self.shapes[i].contains(p):
                    self.current = i
            return self.current
        self.current = next((i for i, s in enumerate(self.shapes) if s.contains(p)), None)
        return self.current
