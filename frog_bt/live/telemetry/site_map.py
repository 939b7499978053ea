"""The static map of a site, as plain geometry (no rerun here): POIs, tour routes, zones.

* :func:`poi_marks` — one mark per distinct position: POIs that share a spot
  (POI1a and POI1b differ only in orientation) share one point labelled with
  their ids, each keeping its own heading.
* :func:`tour_routes` — the tour as the robot drives it at each time of day:
  dock, recruiting POI, every stop with the variant of that time, dock again.
  Consecutive periods that drive through the same positions are merged, so a
  site with variants shows one strip per distinct route, labelled with its
  period ("until 12:00", "after 12:00").
* :func:`zone_outlines` — the site's zones, if its configuration has any
  (circles become polygons), read by duck typing so a config without zones, or
  with a different zone model, only draws fewer outlines.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from datetime import time as dtime
from typing import Any

from frog_bt.config import Site

XY = tuple[float, float]
CIRCLE_SEGMENTS = 48


@dataclass(frozen=True, slots=True)
class PoiMark:
    """A labelled spot on the map and the headings (yaw, radians) of the POIs there."""

    label: str  # the POI ids: "POI1a/POI1b"
    x: float
    y: float
    headings: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Route:
    label: str  # the time of day it applies to
    waypoints: tuple[str, ...]
    points: tuple[XY, ...]


@dataclass(frozen=True, slots=True)
class Outline:
    label: str
    kind: str  # "volume", "special", ...
    points: tuple[XY, ...]  # closed: the last point repeats the first


def yaw_of(qz: float, qw: float) -> float:
    return 2.0 * math.atan2(qz, qw)


def poi_marks(site: Site) -> list[PoiMark]:
    groups: dict[tuple[float, float], list[str]] = {}
    for name, poi in site.pois.items():
        groups.setdefault((round(poi.x, 2), round(poi.y, 2)), []).append(name)
    marks = []
    for names in groups.values():
        first = site.pois[names[0]]
        label = "/".join(names)
        headings = tuple(yaw_of(site.pois[n].z, site.pois[n].w) for n in names)
        marks.append(PoiMark(label, first.x, first.y, headings))
    return marks


def _period_label(start: dtime | None, end: dtime | None) -> str:
    if start is None:
        return f"until {end:%H:%M}" if end is not None else "tour route"
    return f"after {start:%H:%M}" if end is None else f"{start:%H:%M}-{end:%H:%M}"


def _periods(site: Site) -> list[tuple[dtime | None, dtime | None, dtime]]:
    """(start, end, a time of day inside) of each period with its own variants."""
    stops = {s.poi for s in site.tour.stops}
    cuts = sorted(
        {
            v.until
            for name, vs in site.variants.items()
            if name in stops
            for v in vs
            if v.until is not None
        }
    )
    bounds: list[dtime | None] = [None, *cuts, None]
    periods = []
    for start, end in itertools.pairwise(bounds):
        if end is not None:
            inside = end  # a variant holds while the time is at or before its `until`
        elif start is not None:
            inside = (
                dtime(23, 59, 59)
                if start >= dtime(23, 59)
                else dtime(start.hour + (start.minute + 1) // 60, (start.minute + 1) % 60)
            )
        else:
            inside = dtime(12, 0)
        periods.append((start, end, inside))
    return periods


def tour_routes(site: Site) -> list[Route]:
    """The tour's route per period of the day (see the module docstring)."""
    merged: list[tuple[dtime | None, dtime | None, tuple[str, ...], tuple[XY, ...]]] = []
    for start, end, at in _periods(site):
        names = (
            site.tour.dock,
            site.tour.recruit_at,
            *(site.waypoint_for(s.poi, at) for s in site.tour.stops),
            site.tour.dock,
        )
        points = tuple((site.pois[n].x, site.pois[n].y) for n in names)
        if merged and _same(merged[-1][3], points):
            first = merged.pop()
            start, names = first[0], first[2]
        merged.append((start, end, names, points))
    return [Route(_period_label(start, end), names, points) for start, end, names, points in merged]


def _same(a: Sequence[XY], b: Sequence[XY]) -> bool:
    return len(a) == len(b) and all(math.dist(p, q) < 0.01 for p, q in zip(a, b, strict=True))


def circle_points(x: float, y: float, r: float, segments: int = CIRCLE_SEGMENTS) -> tuple[XY, ...]:
    """A closed polygon around the circle (the last point is the first)."""
    points = tuple(
        (x + r * math.cos(2 * math.pi * k / segments), y + r * math.sin(2 * math.pi * k / segments))
        for k in range(segments)
    )
    return (*points, points[0])


def _shape_points(shape: Any) -> tuple[XY, ...] | None:
    circle = getattr(shape, "circle", None)
    if circle is not None:
        return circle_points(float(circle.x), float(circle.y), float(circle.r))
    polygon = getattr(shape, "polygon", None) or getattr(shape, "points", None)
    if polygon:
        points = tuple((float(p[0]), float(p[1])) for p in polygon)
        return (*points, points[0])
    return None


def _outlines(items: Iterable[Any], kind: str, label: Any) -> list[Outline]:
    out = []
    for item in items or ():
        points = _shape_points(item)
        if points is not None:
            out.append(Outline(label(item), kind, points))
    return out


def zone_outlines(site: Site) -> list[Outline]:
    """Volume zones ("Vault Room 80%") and special spots ("toilets"), when configured."""
    zones = getattr(site, "zones", None)
    if zones is None:
        return []
    volume = getattr(zones, "volume", None)
    out = _outlines(
        getattr(volume, "zones", ()),
        "volume",
        lambda z: f"{getattr(z, 'name', '')} {getattr(z, 'percent', '')}%".strip(),
    )
    out += _outlines(
        getattr(zones, "special", ()),
        "special",
        lambda z: str(getattr(z, "spot", getattr(z, "name", ""))),
    )
    return out
