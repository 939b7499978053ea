"""At a stop: the follower check and content, ticked by hand."""

from __future__ import annotations

from bench import Bench, write_tree

from frog_bt.model.frontend import ContentDone, FinishPoi, StartPoi
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS


def test_visitor_follows_when_someone_is_tracked_within_the_radius(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: VisitorFollows, radius: 3, grace: 10}"))
    bench.pose(10.0, 10.0)
    bench.people((1, 14.0, 10.0))  # 4 m away
    assert bench.tick() == RUNNING
    bench.advance(5)
    bench.pose(10.0, 10.0)
    bench.people((1, 12.5, 10.0))
    assert bench.tick() == SUCCESS


def test_visitor_lost_after_the_grace_period(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: VisitorFollows, radius: 3, grace: 10}"))
    bench.pose(10.0, 10.0)
    bench.people()
    assert bench.tick() == RUNNING
    bench.advance(9.9)
    bench.pose(10.0, 10.0)
    bench.people()
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert "visitor lost" in bench.core.last_note


def test_stale_tracking_is_not_taken_for_a_lost_visitor(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: VisitorFollows, radius: 3, grace: 10}"))
    bench.pose(10.0, 10.0)
    bench.people()  # nobody near, but this reading goes stale: the laser drops out
    bench.tick()
    bench.advance(3)
    assert bench.tick() == RUNNING
    assert bench.core.root.feedback_message == "laser tracking or pose stale: waiting"
    bench.advance(7)
    assert bench.tick() == SUCCESS
    assert "stale: assuming the visitor follows" in bench.core.last_note


def test_content_plays_the_chosen_waypoint_and_waits_for_its_own_done(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            """
        root:
          type: Sequence
          memory: true
          children:
            - {type: Navigate, poi: POI2}
            - {type: PlayContent, poi: POI2, part: a}
            - {type: FinishPoi, poi: POI2}
        """,
        )
    )
    bench.tick()
    bench.at("POI2a")
    bench.ros("response", 2)
    assert bench.tick() == RUNNING
    assert bench.take_sent() == [StartPoi("POI2", "POI2a", "a")]
    bench.event(ContentDone("POI1", "a"))
    bench.event(ContentDone("POI2", "b"))
    assert bench.tick() == RUNNING
    bench.event(ContentDone("POI2", "a"))
    assert bench.tick() == SUCCESS
    assert bench.take_sent() == [FinishPoi("POI2")]


def test_silent_front_end_content_times_out_and_the_tour_goes_on(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: PlayContent, poi: POI3, timeout: 60}"))
    bench.tick()
    bench.advance(59)
    assert bench.tick() == RUNNING
    bench.advance(1)
    assert bench.tick() == SUCCESS
    assert "no content_done within 60 s" in bench.core.last_note


def test_content_is_sent_again_when_the_front_end_restarts(tmp_path):
    from frog_bt.model.frontend import FrontendIdle

    bench = Bench(write_tree(tmp_path, "root: {type: PlayContent, poi: POI4}"))
    bench.tick()
    assert bench.take_sent() == [StartPoi("POI4", "POI4", "a")]
    bench.event(FrontendIdle())  # it restarted and lost what it was playing
    assert bench.tick() == RUNNING
    assert bench.take_sent() == [StartPoi("POI4", "POI4", "a")]
    assert bench.tick() == RUNNING
    assert bench.take_sent() == []  # once per restart
    bench.event(ContentDone("POI4", "a"))
    assert bench.tick() == SUCCESS
