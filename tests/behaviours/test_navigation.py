"""Navigate, Retry and skipping, ticked by hand on a ManualClock."""

from __future__ import annotations

import pytest
from bench import AFTERNOON, MORNING, Bench, write_tree

from frog_bt.model import keys
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

NAVIGATE = "root: {type: Navigate, poi: POI1, timeout: 30}"


def goal(bench):
    ((topic, msg),) = bench.take_published()
    assert topic == "/GotoWayPoint"
    return msg


def test_goal_carries_the_poi_pose_in_the_map_frame(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE))
    assert bench.tick() == RUNNING
    msg = goal(bench)
    assert msg["header"]["frame_id"] == "map"
    assert msg["header"]["stamp"] == {"secs": int(MORNING), "nsecs": 0}
    assert msg["pose"]["position"] == {"x": 97.19, "y": 63.02, "z": 0.0}
    assert msg["pose"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.898316, "w": 0.43934}


@pytest.mark.parametrize(
    ("poi", "clock_time", "waypoint"),
    [
        ("POI1", "13:00:00", "POI1a"),
        ("POI1", "13:00:01", "POI1b"),
        ("POI2", "12:00:00", "POI2a"),
        ("POI2", "12:00:01", "POI2b"),
        ("POI3", "23:59:00", "POI3"),
    ],
)
def test_time_of_day_variant_in_madrid(tmp_path, poi, clock_time, waypoint):
    h, m, s = map(int, clock_time.split(":"))
    start = MORNING - 10.5 * 3600 + h * 3600 + m * 60 + s  # MORNING is 10:30 local
    bench = Bench(write_tree(tmp_path, f"root: {{type: Navigate, poi: {poi}}}"), start=start)
    bench.tick()
    msg = goal(bench)
    expected = bench.site.pois[waypoint]
    assert (msg["pose"]["position"]["x"], msg["pose"]["orientation"]["z"]) == (
        expected.x,
        expected.z,
    )
    assert bench.core.board.get(keys.WAYPOINT) == waypoint


def test_succeeds_on_response_2_only_after_active(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE))
    bench.tick()
    bench.ros("response", 1)
    assert bench.tick() == RUNNING
    bench.at("POI1a")
    bench.ros("response", 2)
    assert bench.tick() == SUCCESS


@pytest.mark.parametrize("code", [3, 4])
def test_fails_on_3_or_4(tmp_path, code):
    bench = Bench(write_tree(tmp_path, NAVIGATE))
    bench.tick()
    bench.ros("response", code)
    assert bench.tick() == FAILURE


def test_times_out_on_the_project_clock(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE))
    bench.tick()
    bench.advance(29.9)
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE


def test_response_with_nothing_pending_is_ignored(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            """
        root:
          type: Sequence
          memory: true
          children:
            - {type: FinishPoi, poi: POI1}
            - {type: Navigate, poi: POI1}
        """,
        )
    )
    bench.ros("response", 2)  # before any goal: stale
    bench.tick()  # snapshot drops it, then the goal is sent
    assert bench.core.actions.stale_responses == 1
    assert bench.tick() == RUNNING


def test_retry_resends_then_skip_stop(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            """
        root:
          type: Sequence
          memory: true
          children:
            - type: Selector
              memory: true
              children:
                - {type: Retry, attempts: 2, child: {type: Navigate, poi: POI3}}
                - {type: SkipStop, poi: POI3}
            - type: Selector
              memory: true
              children:
                - {type: Skipped, poi: POI3}
                - {type: FinishPoi, poi: POI3}
        """,
        ),
        start=AFTERNOON,
    )
    bench.tick()
    goal(bench)
    bench.ros("response", 3)
    assert bench.tick() == RUNNING  # retry: the goal is sent again on the next tick
    assert bench.take_published() == []
    bench.tick()
    goal(bench)
    bench.ros("response", 4)
    assert bench.tick() == SUCCESS  # skipped: no content
    assert bench.take_sent() == []
    assert "skipped POI3: navigation kept failing" in bench.core.last_note
