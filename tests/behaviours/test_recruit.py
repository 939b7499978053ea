"""Seeking, approaching and introducing a visitor, ticked by hand."""

from __future__ import annotations

import py_trees
from bench import Bench, write_tree

from frog_bt.frontend.messages import (
    AskTour,
    FinishIntroduction,
    StartIntroduction,
    UserNegative,
    UserPositive,
)
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

SEEK = "root: {type: SeekVisitor}"


def visitor(bench):
    return py_trees.blackboard.Blackboard.storage.get("/visitor")


def test_nearest_facing_person_is_chosen(tmp_path):
    bench = Bench(write_tree(tmp_path, SEEK))
    bench.pose(100.0, 30.0)
    bench.persons((1, 110.0, 30.0, 180.0), (2, 103.0, 30.0, 200.0), (3, 101.0, 30.0, 90.0))
    assert bench.tick() == SUCCESS
    assert visitor(bench) == 2  # 3 is nearer but looks away


def test_facing_bounds_are_exclusive(tmp_path):
    bench = Bench(write_tree(tmp_path, SEEK))
    bench.pose(0.0, 0.0)
    bench.persons((1, 1.0, 0.0, 135.0), (2, 2.0, 0.0, 225.0))
    assert bench.tick() == RUNNING
    bench.persons((1, 1.0, 0.0, 135.01))
    assert bench.tick() == SUCCESS


def test_stale_detections_are_not_acted_on(tmp_path):
    bench = Bench(write_tree(tmp_path, SEEK))
    bench.pose(0.0, 0.0)
    bench.persons((1, 1.0, 0.0, 180.0))
    bench.advance(1.5)  # site recruit.detection_max_age is 1 s
    assert bench.tick() == RUNNING


def recruit_tree(tmp_path):
    return write_tree(tmp_path, """
        root:
          type: Retry
          attempts: null
          child:
            type: Sequence
            memory: true
            children:
              - {type: SeekVisitor}
              - {type: ApproachVisitor}
              - type: FaceStream
                name: faces
                child:
                  type: Sequence
                  memory: true
                  children:
                    - {type: StartIntroduction}
                    - {type: WaitEvent, event: finish_introduction}
                    - {type: AskTour}
                    - {type: WaitAnswer}
        """)


def test_rejected_approach_seeks_again_and_declined_visitor_is_skipped(tmp_path):
    bench = Bench(recruit_tree(tmp_path))
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 7})]
    bench.ros("response", 4)  # rejected: seek again, same nearest visitor
    bench.tick()
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 7})]
    bench.ros("response", 2)
    bench.tick()
    assert bench.take_published() == [("/ICL_command", {"data": "start"})]
    assert bench.take_sent() == [StartIntroduction(icl=True)]
    bench.event(FinishIntroduction())
    bench.tick()
    assert bench.take_sent() == [AskTour(engaged=None)]
    bench.event(UserNegative())
    bench.tick()  # declined: face stream stopped, 7 excluded
    assert bench.take_published() == [("/ICL_command", {"data": "stop"})]
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 8})]
    bench.ros("response", 2)
    bench.tick()
    bench.event(FinishIntroduction())
    bench.tick()
    bench.event(UserPositive())
    assert bench.tick() == SUCCESS
    assert bench.take_published()[-1] == ("/ICL_command", {"data": "stop"})


def test_face_stream_is_stopped_when_the_scope_is_interrupted(tmp_path):
    bench = Bench(recruit_tree(tmp_path))
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0))
    bench.tick()
    bench.ros("response", 2)
    bench.tick()
    bench.take_published()
    bench.core.halt()
    assert bench.take_published() == [("/ICL_command", {"data": "stop"})]
    bench.core.halt()  # a second halt sends nothing more
    assert bench.take_published() == []


def test_finish_introduction_that_came_before_the_wait_does_not_count(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: WaitEvent, event: finish_introduction, "
                             "timeout: 5}"))
    bench.event(FinishIntroduction())
    bench.tick()  # the event arrived before the leaf started: not this one
    bench.advance(5)
    assert bench.tick() == FAILURE
