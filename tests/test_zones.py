"""Zone geometry and hysteresis."""

from __future__ import annotations

from frog_bt.maths.zones import Membership, Shape, point_in_polygon

SQUARE = ((0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0))


def test_point_in_polygon():
    assert point_in_polygon((5, 5), SQUARE)
    assert not point_in_polygon((11, 5), SQUARE)
    assert not point_in_polygon((5, -0.1), SQUARE)


def test_outside_distance_of_circle_and_polygon():
    assert Shape(center=(0, 0), radius=2).outside_by((3, 4)) == 3.0
    assert Shape(points=SQUARE).outside_by((13, 14)) == 5.0
    assert Shape(points=SQUARE).outside_by((5, 5)) == 0.0


def test_hysteresis_stops_flapping_on_a_border():
    m = Membership([Shape(center=(0, 0), radius=10)], hysteresis=1.0)
    path = [12.0, 9.9, 10.1, 9.95, 10.5, 10.9, 11.01, 10.5, 9.99]
    assert [m.update((x, 0.0)) for x in path] == [None, 0, 0, 0, 0, 0, None, None, 0]


def test_first_listed_zone_wins_where_zones_meet():
    m = Membership(
        [Shape(points=SQUARE), Shape(points=((10, 0), (20, 0), (20, 10), (10, 10)))], hysteresis=1.0
    )
    assert m.update((15, 5)) == 1
    assert m.update((10.5, 5)) == 1  # within 1 m of the first: stays in the second
    assert m.update((9.0, 5)) == 0  # fully inside the first
