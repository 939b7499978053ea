"""The robot model, stepped by hand: navigation, docking, visitors, faces, diagnostics."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest
from rosmsgs import (
    decode_diagnostics,
    decode_face_data,
    decode_person_detections,
    decode_pose,
    decode_tracked_people,
    encode_int32,
    encode_pose,
    encode_string,
)

from frog_bt.sim.faces import EngagementScript
from frog_bt.sim.navigation import drive
from frog_bt.sim.world import World

DT = 0.1
Out = tuple[str, dict[str, Any]]
MakeWorld = Callable[..., World]
VISITOR = {"id": 7, "position": [103.0, 36.0], "facing": True}


def run(w: World, seconds: float) -> list[Out]:
    """Step ``w`` for ``seconds`` of simulated time; everything it published."""
    out: list[Out] = []
    for _ in range(round(seconds / DT)):
        out += w.step(DT)
    return out


def on(outs: list[Out], topic: str) -> list[dict[str, Any]]:
    return [msg for t, msg in outs if t == topic]


def codes(outs: list[Out]) -> list[int]:
    return [msg["data"] for msg in on(outs, "/FROG_response")]


def goal(x: float, y: float, qz: float = 0.0, qw: float = 1.0) -> dict[str, Any]:
    return encode_pose(x, y, qz, qw, 0.0)


def undocked(make: MakeWorld, **data: Any) -> World:
    data.setdefault("robot", {"docked": False})
    return make(**data)


def pose_of(w: World) -> tuple[float, float]:
    return w.pose.x, w.pose.y


# ------------------------------------------------------------------ publishing


def test_starts_docked_at_the_shop_and_publishes_at_its_rates(world: MakeWorld, pois: dict) -> None:
    w = world(visitors=[VISITOR])
    assert w.docking_state == "docked" and w.now == w.scenario.start_epoch
    outs = run(w, 1.0)
    poses = [decode_pose(m) for m in on(outs, "/FROG_pose")]
    assert len(poses) == 10
    shop = pois["SHOP"]
    assert (poses[-1].x, poses[-1].y) == pytest.approx(shop[:2])
    assert (poses[-1].qz, poses[-1].qw) == shop[2:]  # exactly as in the POI table
    assert poses[-1].frame_id == "map" and poses[-1].stamp == pytest.approx(w.now)
    assert len(on(outs, "/UvA_PersonDetectionAndPose")) == 5
    assert len(on(outs, "/PeopleUPO")) == 5
    assert [m["data"] for m in on(outs, "/docking/state")] == ["docked"]
    assert len(on(outs, "/diagnostic")) == 1
    assert on(outs, "/ICL_FaceDataStream") == []


# ------------------------------------------------------------------ navigation


def test_drive_is_a_pure_straight_line_step() -> None:
    assert drive(0, 0, 10, 0, 0.6, 1.0) == (pytest.approx(0.6), 0.0, False)
    assert drive(0, 0, 0.5, 0, 0.6, 1.0) == (0.5, 0, True)
    assert drive(0, 0, 0.64, 0, 0.6, 1.0) == (0.64, 0, True)  # within 0.05 m: arrived


def test_goal_drives_at_speed_and_succeeds_with_the_goal_orientation(world: MakeWorld) -> None:
    w = undocked(world, robot={"docked": False, "pose": {"x": 0, "y": 0}})
    qz, qw = math.sin(0.5), math.cos(0.5)
    assert codes(w.handle("/GotoWayPoint", goal(6.0, 0.0, qz, qw))) == [1]
    outs = run(w, 5.0)
    assert w.pose.x == pytest.approx(3.0, abs=1e-6) and w.pose.yaw == pytest.approx(0.0)
    assert codes(outs) == []
    outs = run(w, 5.1)
    assert codes(outs) == [2]
    assert pose_of(w) == (6.0, 0.0)
    assert w.pose.quaternion == pytest.approx((qz, qw))
    assert decode_pose(on(outs, "/FROG_pose")[-1]).yaw == pytest.approx(1.0)


def test_goal_refused_while_docked(world: MakeWorld) -> None:
    w = world()
    assert codes(w.handle("/GotoWayPoint", goal(100, 20))) == [4]
    assert codes(run(w, 2.0)) == [] and w.navigator.active is None


def test_a_new_goal_replaces_the_active_one(world: MakeWorld) -> None:
    w = undocked(world, robot={"docked": False, "pose": {"x": 0, "y": 0}})
    w.handle("/GotoWayPoint", goal(10, 0))
    run(w, 1.0)
    assert codes(w.handle("/GotoWayPoint", goal(0, 1))) == [1]
    outs = run(w, 3.0)
    assert codes(outs) == [2] and pose_of(w) == (0, 1)


def test_the_nth_goal_fails_after_some_driving(world: MakeWorld) -> None:
    w = undocked(
        world,
        robot={"docked": False, "pose": {"x": 0, "y": 0}},
        navigation={"failures": [{"goal": 2, "result": "failed", "after": 2}]},
    )
    w.handle("/GotoWayPoint", goal(1, 0))
    assert codes(run(w, 2.0)) == [2]
    w.handle("/GotoWayPoint", goal(11, 0))
    outs = run(w, 1.9)
    assert codes(outs) == []
    outs = run(w, 0.2)
    assert codes(outs) == [3]
    stopped = pose_of(w)
    assert stopped[0] == pytest.approx(1 + 2 * 0.6, abs=0.07)
    run(w, 2.0)
    assert pose_of(w) == stopped
    w.handle("/GotoWayPoint", goal(11, 0))  # the third goal is not picked
    assert codes(run(w, 20)) == [2]


def test_the_first_k_goals_to_a_poi_abort(world: MakeWorld, pois: dict) -> None:
    w = undocked(
        world,
        robot={"docked": False, "start": "SHOP"},
        navigation={"failures": [{"poi": "POI0", "times": 2, "result": "aborted", "after": 1}]},
    )
    x, y, z, qw = pois["POI0"]
    for _ in range(2):
        w.handle("/GotoWayPoint", goal(x + 0.3, y, z, qw))  # within 0.5 m: still POI0
        assert codes(run(w, 1.5)) == [4]
    w.handle("/GotoWayPoint", goal(x, y, z, qw))
    assert codes(run(w, 60)) == [2]


# ------------------------------------------------------------------ docking


def test_undock_then_dock(world: MakeWorld, pois: dict) -> None:
    w = world()
    out = w.handle("/docking/dock", encode_string("undock"))
    assert out == [("/docking/state", {"data": "undocking"})]
    assert "undocked" not in [m["data"] for m in on(run(w, 4.9), "/docking/state")]
    assert w.docking_state == "undocking"
    assert run(w, 0.1)[0] == ("/docking/state", {"data": "undocked"})
    w.handle("/GotoWayPoint", goal(pois["SHOP"][0] + 1.0, pois["SHOP"][1]))
    run(w, 3.0)
    assert w.handle("/docking/dock", encode_string("dock")) == [
        ("/docking/state", {"data": "docking"})
    ]
    assert w.navigator.active is None
    states = [m["data"] for m in on(run(w, 10.0), "/docking/state")]
    assert states[-1] == "docked" and "failed" not in states
    assert pose_of(w) == pytest.approx(pois["SHOP"][:2])


def test_docking_far_from_the_dock_fails(world: MakeWorld) -> None:
    w = undocked(world, robot={"docked": False, "pose": {"x": 50, "y": 50}})
    w.handle("/docking/dock", encode_string("dock"))
    assert on(run(w, 10.0), "/docking/state")[-1] == {"data": "failed"}


def test_scripted_undock_failures(world: MakeWorld) -> None:
    w = world(docking={"undock_failures": 1, "undock_time": 2})
    w.handle("/docking/dock", encode_string("undock"))
    assert on(run(w, 2.0), "/docking/state")[-1] == {"data": "failed"}
    assert w.docking.docked
    w.handle("/docking/dock", encode_string("undock"))
    assert on(run(w, 2.0), "/docking/state")[-1] == {"data": "undocked"}


def test_asking_for_the_current_state_repeats_it(world: MakeWorld) -> None:
    w = world()
    assert w.handle("/docking/dock", encode_string("dock")) == [
        ("/docking/state", {"data": "docked"})
    ]
    assert w.handle("/docking/dock", encode_string("fly")) == []


# ------------------------------------------------------------------ visitors


def near_visitor(make: MakeWorld, **visitor: Any) -> World:
    spec = {**VISITOR, **visitor}
    return make(robot={"docked": False, "pose": {"x": 104.0, "y": 33.0}}, visitors=[spec])


def test_detections_within_range_with_orientation(world: MakeWorld) -> None:
    w = world(
        robot={"docked": False, "pose": {"x": 0, "y": 0}},
        visitors=[
            {"id": 1, "position": [3, 4], "facing": True},
            {"id": 2, "position": [0, 5], "orientation": 40},
            {"id": 3, "position": [0, -4], "facing": False},
            {"id": 4, "position": [20, 0]},
            {"id": 5, "position": [1, 1], "appear_at": "never"},
            {"id": 6, "position": [1, 2], "appear_at": 3},
        ],
    )
    persons = decode_person_detections(on(run(w, 0.2), "/UvA_PersonDetectionAndPose")[-1])
    assert {p.id: p.orientation for p in persons.persons} == {1: 180.0, 2: 40.0, 3: 90.0}
    assert persons.persons[0].position.x == 3.0
    people = decode_tracked_people(on(run(w, 3.0), "/PeopleUPO")[-1])
    assert {p.id for p in people.people} == {1, 2, 3, 6}


def test_approach_succeeds_and_places_the_robot_in_front(world: MakeWorld) -> None:
    w = near_visitor(world)
    assert codes(w.handle("/ApproachPeopleFar", encode_int32(7))) == [1]
    assert codes(run(w, 2.9)) == []
    assert codes(run(w, 0.1)) == [2]
    v = w.visitors[7]
    assert math.hypot(w.pose.x - v.x, w.pose.y - v.y) == pytest.approx(1.0)
    assert math.atan2(v.y - w.pose.y, v.x - w.pose.x) == pytest.approx(w.pose.yaw)
    assert w.current_visitor is v and v.state == "with_robot"


def test_scripted_approach_results_are_used_in_order(world: MakeWorld) -> None:
    w = near_visitor(world, approach=["aborted", "failed"])
    results = []
    for _ in range(3):
        w.handle("/ApproachPeopleFar", encode_int32(7))
        results += codes(run(w, 3.0))
    assert results == [4, 3, 2]


def test_approaching_someone_not_in_view_is_refused(world: MakeWorld) -> None:
    w = near_visitor(world)
    assert codes(w.handle("/ApproachPeopleFar", encode_int32(99))) == [4]
    assert codes(world().handle("/ApproachPeopleFar", encode_int32(7))) == [4]  # docked


def start_tour(w: World) -> None:
    w.handle("/ApproachPeopleFar", encode_int32(7))
    run(w, 3.0)
    w.on_frontend("out", "user_positive", {})


def test_the_visitor_follows_once_the_tour_starts(world: MakeWorld, pois: dict) -> None:
    w = near_visitor(world)
    start_tour(w)
    v = w.visitors[7]
    assert v.state == "following"
    x, y, z, qw = pois["POI1a"]
    w.handle("/GotoWayPoint", goal(x, y, z, qw))
    run(w, 10.0)
    assert math.hypot(w.pose.x - v.x, w.pose.y - v.y) == pytest.approx(1.2)
    assert codes(run(w, 60.0)) == [2]
    assert math.hypot(w.pose.x - v.x, w.pose.y - v.y) < 4.0
    assert 7 in {p.id for p in decode_tracked_people(on(run(w, 0.2), "/PeopleUPO")[-1]).people}


def test_the_visitor_wanders_off_when_the_robot_heads_to_a_poi(
    world: MakeWorld, pois: dict
) -> None:
    w = near_visitor(world, wander_off={"heading_to": "POI2"})
    start_tour(w)
    v = w.visitors[7]
    w.handle("/GotoWayPoint", goal(*pois["POI1a"]))
    run(w, 5.0)
    assert v.state == "following"
    w.handle("/GotoWayPoint", goal(*pois["POI2a"]))
    assert v.state == "leaving"
    outs = run(w, 25.0)
    assert v.state == "gone"
    assert 7 not in {
        p.id for p in decode_person_detections(on(outs, "/UvA_PersonDetectionAndPose")[-1]).persons
    }


def test_the_visitor_wanders_off_at_a_time(world: MakeWorld) -> None:
    w = near_visitor(world, wander_off={"at": 10})
    start_tour(w)
    run(w, 6.9)
    assert w.visitors[7].state == "following"
    run(w, 0.2)
    assert w.visitors[7].state == "leaving"


def test_a_visitor_who_says_no_leaves(world: MakeWorld) -> None:
    w = near_visitor(world, answer="negative")
    w.handle("/ApproachPeopleFar", encode_int32(7))
    run(w, 3.0)
    w.on_frontend("out", "user_negative", {})
    assert w.visitors[7].state == "leaving" and w.current_visitor is None


def test_after_the_tour_a_returning_visitor_comes_back_as_someone_new(world: MakeWorld) -> None:
    w = near_visitor(world, after_tour="return")
    start_tour(w)
    w.on_frontend("in", "tour", {"state": "started", "reason": ""})
    w.on_frontend("in", "tour", {"state": "ended", "reason": "done"})
    assert w.visitors[7].state == "leaving" and w.current_visitor is None
    fresh = w.visitors[1007]
    assert fresh.state == "present" and (fresh.x, fresh.y) == (103.0, 36.0)


# ------------------------------------------------------------------ faces


def faces(outs: list[Out]) -> list[Any]:
    return [f for m in on(outs, "/ICL_FaceDataStream") for f in decode_face_data(m).faces]


def test_faces_only_between_start_and_stop(world: MakeWorld) -> None:
    w = near_visitor(world)
    start_tour(w)
    assert on(run(w, 1.0), "/ICL_FaceDataStream") == []
    w.handle("/ICL_command", encode_string("start"))
    outs = run(w, 1.0)
    assert len(on(outs, "/ICL_FaceDataStream")) == 10
    samples = faces(outs)
    assert len(samples) == 10 and all(f.id == 7 and f.facing for f in samples)
    assert all(0.2 <= f.engagement <= 0.9 and f.distance == 1.0 for f in samples)
    w.handle("/ICL_command", encode_string("stop"))
    assert on(run(w, 1.0), "/ICL_FaceDataStream") == []


def test_no_faces_without_a_current_visitor(world: MakeWorld) -> None:
    w = near_visitor(world)
    w.handle("/ICL_command", encode_string("start"))
    outs = run(w, 0.5)
    assert len(on(outs, "/ICL_FaceDataStream")) == 5 and faces(outs) == []


@pytest.mark.parametrize(
    ("profile", "check"),
    [
        ("engaged", lambda f: 0.2 <= f.engagement <= 0.9),
        ("bored", lambda f: -0.9 <= f.engagement <= -0.2),
        ("far", lambda f: f.distance > 2.0 and f.facing),
        ("not_facing", lambda f: not f.facing and f.distance == 1.0),
    ],
)
def test_engagement_profiles(profile: str, check: Callable[[Any], bool]) -> None:
    samples = [EngagementScript(profile, 7, seed=1).sample() for _ in range(3)]
    script = EngagementScript(profile, 7, seed=1)
    many = [script.sample() for _ in range(100)]
    assert all(check(f) for f in many)
    assert samples[0] == many[0]  # deterministic


def test_mixed_and_explicit_engagement() -> None:
    mixed = EngagementScript("mixed", 1)
    values = [mixed.sample().engagement for _ in range(40)]
    assert max(values) > 0.6 and min(values) < -0.6
    assert sum(v > 0 for v in values) == 20
    listed = EngagementScript((0.5, -0.25), 1)
    assert [listed.sample().engagement for _ in range(3)] == [0.5, -0.25, 0.5]


# ------------------------------------------------------------------ diagnostics


def battery(outs: list[Out]) -> float | None:
    return decode_diagnostics(on(outs, "/diagnostic")[-1]).battery


def test_battery_drains_off_the_dock_and_charges_on_it(world: MakeWorld) -> None:
    w = undocked(world, battery={"start": 80, "drain_per_hour": 6, "charge_per_hour": 30})
    assert battery(run(w, 1.0)) == pytest.approx(80.0, abs=0.05)
    assert battery(run(w, 599.0)) == pytest.approx(79.0, abs=0.05)
    docked = world(battery={"start": 80, "charge_per_hour": 36})
    assert battery(run(docked, 100.0)) == pytest.approx(81.0, abs=0.05)


def test_scripted_faults(world: MakeWorld) -> None:
    w = world(
        faults=[
            {"at": 3, "name": "motors", "level": 2, "message": "hot", "duration": 2},
            {"at": 4, "name": "laser", "level": 3},
        ]
    )
    assert decode_diagnostics(on(run(w, 2.0), "/diagnostic")[-1]).faults == ()
    assert decode_diagnostics(on(run(w, 2.0), "/diagnostic")[-1]).faults == ("motors: hot", "laser")
    assert decode_diagnostics(on(run(w, 2.0), "/diagnostic")[-1]).faults == ("laser",)
    status = on(run(w, 1.0), "/diagnostic")[-1]["status"][0]
    assert status["name"] == "battery" and status["level"] == 0
    assert status["hardware_id"] == "frog"


def test_malformed_input_is_counted_not_fatal(world: MakeWorld) -> None:
    w = world()
    assert w.handle("/GotoWayPoint", {"pose": "nowhere"}) == []
    assert w.handle("/docking/dock", {"data": 5}) == []
    assert w.handle("/somewhere/else", {"data": 5}) == []
    assert w.malformed == 2


# ------------------------------------------------------------------ a whole tour


def test_a_whole_tour_by_hand(world: MakeWorld, pois: dict) -> None:
    """Undock, recruit at POI0, visit every stop with the visitor behind, dock."""
    w = world(visitors=[VISITOR])

    def go(name: str) -> None:
        assert codes(w.handle("/GotoWayPoint", goal(*pois[name]))) == [1]
        for _ in range(3000):
            if codes(w.step(DT)):
                break
        assert pose_of(w) == pytest.approx(pois[name][:2]), name

    w.handle("/docking/dock", encode_string("undock"))
    run(w, 5.0)
    go("POI0")
    seen = decode_person_detections(on(run(w, 0.2), "/UvA_PersonDetectionAndPose")[-1])
    assert [(p.id, p.orientation) for p in seen.persons] == [(7, 180.0)]
    start_tour(w)
    for name in ("POI1a", "POI2a", "POI3", "POI4", "POI5", "TEMP", "END"):
        go(name)
        v = w.visitors[7]
        assert math.hypot(v.x - w.pose.x, v.y - w.pose.y) <= 1.3, name
    w.on_frontend("in", "tour", {"state": "ended", "reason": ""})
    go("SHOP")
    w.handle("/docking/dock", encode_string("dock"))
    run(w, 10.0)
    assert w.docking_state == "docked"
    assert w.elapsed < 40 * 60
