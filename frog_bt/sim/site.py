"""The POI table the simulator matches goals against.

The simulator only needs where each POI is: ``name -> (x, y, z, w)`` (map
frame; z, w the orientation quaternion's z and w), read from the ``pois:``
mapping of ``config/site.yaml``. A ``/GotoWayPoint`` goal "goes to" every POI
within :data:`MATCH_RADIUS` of it, and a scenario naming a POI matches either
that exact name or its time-of-day variants (``POI2`` matches ``POI2a`` and
``POI2b``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path

from frog_bt.config import DEFAULT_CONFIG, load_site

PoiPose = tuple[float, float, float, float]
MATCH_RADIUS = 0.5  # metres


def load_pois(path: str | Path = DEFAULT_CONFIG) -> dict[str, PoiPose]:
    """``name -> (x, y, z, w)`` from a site file, validated as the executive validates it."""
    return {name: (p.x, p.y, p.z, p.w) for name, p in load_site(path).pois.items()}


def pois_at(
    pois: Mapping[str, PoiPose], x: float, y: float, radius: float = MATCH_RADIUS
) -> frozenset[str]:
    """Names of every POI within ``radius`` of (x, y) (POI1a and POI1b share a spot)."""
    return frozenset(
        name for name, (px, py, _, _) in pois.items() if math.hypot(px - x, py - y) <= radius
    )


def poi_matches(spec: str, names: Iterable[str]) -> bool:
    """True when scenario POI ``spec`` is one of ``names`` or a variant of it (POI2 ~ POI2b)."""
    return any(
        name == spec
        or (
            len(name) == len(spec) + 1
            and name.startswith(spec)
            and name[-1].isalpha()
            and name[-1].islower()
        )
        for name in names
    )
