"""Engagement, projector prewarm and location awareness, end to end on sim time."""

from __future__ import annotations

import itertools
import math

import pytest
from tour import tour

from frog_bt.model.frontend import Engagement

VISITOR = {"id": 7, "position": [103.0, 36.0], "facing": True}


def story(t, poi):
    return [c for c in t.frontend_commands("start_poi", "finish_poi") if c.split()[1] == poi]


@pytest.fixture(scope="module")
def morning():
    # At the robot's real speed (the site's estimate of the time to arrival, which warms
    # the projector, assumes it), not the fast tours' 2.4 m/s.
    return tour({"start_time": "2026-06-01T10:30:00+02:00", "navigation": {"speed": 0.6}})


def test_engaged_visitor_gets_both_parts_with_counted_decisions(morning):
    assert story(morning, "POI1") == [
        "start_poi POI1 POI1a a",
        "start_poi POI1 POI1a b",
        "finish_poi POI1",
    ]
    assert story(morning, "POI2")[:2] == ["start_poi POI2 POI2a a", "start_poi POI2 POI2a b"]
    decisions = {about: d for about, d in morning.summary.decisions}
    assert set(decisions) == {"introduction", "POI1", "POI2"}
    for d in decisions.values():
        assert d.engaged is True and d.stored > 20 and d.votes >= 2 * math.ceil(0.15 * d.stored)
    assert "ask_tour True" in morning.frontend_commands("ask_tour")


def test_meter_is_sent_every_two_seconds_while_faces_stream(morning):
    # times on the executive's own clock: exact, whatever the load on the machine
    meters = [(t, m) for t, m in morning.sent if isinstance(m, Engagement)]
    assert len(meters) > 10
    # windows are exactly 2 s; each is sent on the first tick (10 Hz) after its end
    gaps = [b[0] - a[0] for a, b in itertools.pairwise(meters) if b[0] - a[0] < 3]
    assert all(abs(g - 2.0) <= 0.2 + 1e-9 for g in gaps)
    assert abs(sum(gaps) / len(gaps) - 2.0) < 0.01
    assert all(-1 <= m.level <= 1 for _, m in meters if m.level is not None)
    assert len(morning.sim.received("engagement")) == len(meters)


def test_bored_visitor_gets_part_a_only():
    t = tour({"visitors": [{**VISITOR, "faces": "bored"}]})
    assert t.outcome.code == 0, t.outcome.reason
    assert story(t, "POI1") == ["start_poi POI1 POI1a a", "finish_poi POI1"]
    assert story(t, "POI2") == ["start_poi POI2 POI2a a", "finish_poi POI2"]
    assert "ask_tour False" in t.frontend_commands("ask_tour")


@pytest.mark.parametrize("faces", ["far", "not_facing"])
def test_faces_too_far_or_not_facing_are_not_stored(faces):
    t = tour({"visitors": [{**VISITOR, "faces": faces}]})
    assert t.outcome.code == 0, t.outcome.reason
    assert all(d.stored == 0 and d.engaged is None for _, d in t.summary.decisions)
    assert story(t, "POI1") == ["start_poi POI1 POI1a a", "finish_poi POI1"]
    assert "ask_tour None" in t.frontend_commands("ask_tour")
    assert {r.payload["level"] for r in t.sim.received("engagement")} == {None}


def first(records, predicate, after=-math.inf):
    return next(r for r in records if r.t >= after and predicate(r))


def test_projector_is_warm_on_arrival_at_poi3_and_off_after_it(morning):
    log = list(morning.sim.log)
    goal = first(
        log,
        lambda r: r.channel == "/GotoWayPoint" and morning.summary.waypoint_of(r.payload) == "POI3",
    )
    arrived = first(
        log, lambda r: r.channel == "/FROG_response" and r.payload["data"] == 2, after=goal.t
    )
    on = [r for r in log if r.channel == "projector"]
    assert [r.payload["on"] for r in on] == [True, False]
    assert on[0].t >= goal.t and arrived.t - on[0].t >= 20.0
    finish = first(log, lambda r: r.channel == "finish_poi" and r.payload["poi"] == "POI3")
    next_goal = first(log, lambda r: r.channel == "/GotoWayPoint", after=finish.t)
    assert finish.t <= on[1].t <= next_goal.t


def test_volume_changes_at_the_zone_crossings_of_the_route(morning):
    volumes = [r.payload["percent"] for r in morning.sim.received("volume")]
    # shop (docked) 50 -> outdoors 100 -> Tapestry/Vault Rooms 80 -> outdoors 100 -> shop 50
    assert volumes == [50, 100, 80, 100, 50]


def test_follow_me_on_while_guiding_and_off_within_the_arrival_range(morning):
    log = list(morning.sim.log)
    follow = [r for r in log if r.channel == "follow_me"]
    assert [r.payload["on"] for r in follow] == [True, False] * 7  # POI1 .. END
    off = follow[1]
    pose = [r for r in log if r.channel == "/FROG_pose" and r.t <= off.t][-1].payload
    p = pose["pose"]["position"]
    target = morning.site.pois["POI1a"]
    distance = math.hypot(p["x"] - target.x, p["y"] - target.y)
    assert 4.0 < distance <= 5.0 + 0.6  # entered the 5 m range within one pose period


def test_each_special_content_spot_fires_once(morning):
    spots = [r.payload["spot"] for r in morning.sim.received("special_content")]
    assert sorted(spots) == ["bar", "shop", "toilets"]
