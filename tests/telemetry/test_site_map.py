"""The static map as geometry: POI marks, tour routes per period of the day, zones."""

from __future__ import annotations

import math
from datetime import time
from types import SimpleNamespace

from frog_bt.config import Variant, load_site
from frog_bt.live.telemetry.site_map import circle_points, poi_marks, tour_routes, zone_outlines


def test_pois_sharing_a_spot_share_a_mark_with_both_headings():
    site = load_site()
    marks = {m.label: m for m in poi_marks(site)}
    assert "POI1a/POI1b" in marks and "POI1a" not in marks
    assert len(marks["POI1a/POI1b"].headings) == 2
    assert len(marks) == len(site.pois) - 1
    shop = marks["SHOP"]
    assert (shop.x, shop.y) == (site.pois["SHOP"].x, site.pois["SHOP"].y)
    assert math.isclose(shop.headings[0], 2 * math.atan2(site.pois["SHOP"].z, site.pois["SHOP"].w))


def test_routes_follow_the_variants_of_each_period_and_merge_identical_ones():
    site = load_site()
    routes = tour_routes(site)
    # POI1 changes at 13:00 but POI1a and POI1b share a spot: 12:00-13:00 and after
    # 13:00 drive the same way, so they merge into "after 12:00".
    assert [r.label for r in routes] == ["until 12:00", "after 12:00"]
    morning, afternoon = routes
    assert morning.waypoints[:4] == ("SHOP", "POI0", "POI1a", "POI2a")
    assert afternoon.waypoints[3] == "POI2b"
    for route in routes:
        assert route.waypoints[0] == route.waypoints[-1] == site.tour.dock
        assert len(route.points) == len(site.tour.stops) + 3


def test_routes_without_variants_and_with_three_periods():
    site = load_site()
    plain = site.model_copy(update={"variants": {}})
    plain = plain.model_copy(
        update={
            "tour": site.tour.model_copy(
                update={"stops": [s for s in site.tour.stops if s.poi not in site.variants]}
            )
        }
    )
    assert [r.label for r in tour_routes(plain)] == ["tour route"]
    three = site.model_copy(
        update={
            "variants": {
                "POI1": [Variant(waypoint="POI1a", until=time(11, 0)), Variant(waypoint="POI2b")],
                "POI2": [Variant(waypoint="POI2a", until=time(12, 0)), Variant(waypoint="POI2b")],
            }
        }
    )
    assert [r.label for r in tour_routes(three)] == ["until 11:00", "11:00-12:00", "after 12:00"]


def test_zones_become_closed_outlines():
    site = load_site()
    outlines = {z.label: z for z in zone_outlines(site)}
    if not outlines:  # a config without zones draws none
        return
    for outline in outlines.values():
        assert outline.points[0] == outline.points[-1]
        assert outline.kind in ("volume", "special")
    volume = [z for z in outlines.values() if z.kind == "volume"]
    assert all(z.label.endswith("%") for z in volume)


def test_zones_are_read_by_duck_typing():
    assert zone_outlines(SimpleNamespace()) == []  # type: ignore[arg-type]
    site = SimpleNamespace(
        zones=SimpleNamespace(
            volume=SimpleNamespace(
                zones=[
                    SimpleNamespace(
                        name="hall", percent=60, circle=SimpleNamespace(x=0, y=0, r=2), polygon=None
                    ),
                    SimpleNamespace(
                        name="room", percent=80, circle=None, polygon=[(0, 0), (1, 0), (1, 1)]
                    ),
                ]
            ),
            special=[SimpleNamespace(spot="bar", circle=None, polygon=None)],
        )
    )
    outlines = zone_outlines(site)  # type: ignore[arg-type]
    assert [(z.label, z.kind, len(z.points)) for z in outlines] == [
        ("hall 60%", "volume", 49),
        ("room 80%", "volume", 4),
    ]
    assert outlines[0].points == circle_points(0.0, 0.0, 2.0)
