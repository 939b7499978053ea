"""Seeking, approaching and introducing a visitor, ticked by hand."""

from __future__ import annotations

import itertools

import pytest
from bench import Bench, write_tree

from frog_bt.errors import TreeError
from frog_bt.model import keys
from frog_bt.model.frontend import (
    AskTour,
    Engagement,
    FinishIntroduction,
    StartIntroduction,
    UserNegative,
    UserPositive,
)
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

SEEK = "root: {type: SeekVisitor}"


def visitor(bench):
    return bench.core.board.get(keys.VISITOR)


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
    return write_tree(
        tmp_path,
        """
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
                    - {type: WaitEvent, event: finish_introduction, timeout: introduction,
                       on_timeout: success}
                    - {type: AskTour}
                    - {type: WaitAnswer}
        """,
    )


def test_rejected_approach_seeks_someone_else_and_declined_visitor_is_skipped(tmp_path):
    bench = Bench(recruit_tree(tmp_path))
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 7})]
    bench.ros("response", 4)  # rejected: seek again, someone else (7 cools down)
    bench.tick()
    bench.tick()
    assert bench.take_published() == []  # not before recruit.approach_interval (5 s)
    bench.advance(4.9)
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == []
    bench.advance(0.1)
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 8})]
    bench.ros("response", 3)  # 8 fails too: 7 is still cooling down, nobody to approach
    bench.tick()
    bench.advance(30)
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
    bench.tick()
    assert bench.take_published() == []
    bench.advance(30)  # 60 s (recruit.retry_after) since 7 failed: 7 again
    bench.persons((7, 2.0, 0.0, 180.0), (8, 4.0, 0.0, 170.0))
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
    bench.advance(5)  # the approach interval since the approach of 7
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


def test_a_person_whose_approach_always_fails_is_approached_once_a_minute(tmp_path):
    bench = Bench(recruit_tree(tmp_path))
    bench.pose(0.0, 0.0)
    sent = []
    t0 = bench.clock.now()
    for _ in range(3000):  # 5 minutes at 10 Hz
        bench.persons((7, 2.0, 0.0, 180.0))
        bench.tick()
        for topic, msg in bench.take_published():
            sent.append((round(bench.clock.now() - t0, 1), topic, msg["data"]))
            bench.ros("response", 4)
        bench.advance(0.1)
    # the failure is seen a tick or two after the approach; 60 s from then on
    times = [t for t, *_ in sent]
    assert len(times) == 5
    assert all(60 < b - a <= 60.3 for a, b in itertools.pairwise(times))
    assert {(topic, data) for _, topic, data in sent} == {("/ApproachPeopleFar", 7)}
    assert "approach of visitor 7 aborted: seek again (not them for 60 s)" in [
        note.text for note in bench.core.journal.notes
    ]


def test_lost_finish_introduction_asks_the_visitor_after_the_timeout(tmp_path):
    bench = Bench(recruit_tree(tmp_path))
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0))
    bench.tick()
    bench.ros("response", 2)
    bench.tick()
    assert bench.take_sent() == [StartIntroduction(icl=True)]
    bench.advance(299.9)  # site timeouts.introduction is 300 s
    bench.tick()
    assert [m for m in bench.take_sent() if not isinstance(m, Engagement)] == []
    bench.advance(0.1)
    bench.tick()
    assert [m for m in bench.take_sent() if not isinstance(m, Engagement)] == [
        AskTour(engaged=None)
    ]
    kinds = [i.kind for i in bench.core.journal.incidents]
    assert kinds == ["event missing"]


def test_a_wait_without_a_bound_is_a_load_error(tmp_path):
    with pytest.raises(TreeError, match=r"root\.timeout: missing required key"):
        Bench(write_tree(tmp_path, "root: {type: WaitEvent, event: finish_introduction}"))


def test_finish_introduction_that_came_before_the_wait_does_not_count(tmp_path):
    bench = Bench(
        write_tree(tmp_path, "root: {type: WaitEvent, event: finish_introduction, timeout: 5}")
    )
    bench.event(FinishIntroduction())
    bench.tick()  # the event arrived before the leaf started: not this one
    bench.advance(5)
    assert bench.tick() == FAILURE


def test_no_answer_within_the_site_timeout_declines_and_seeks_again(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            "root: {type: Sequence, memory: true, children: ["
            "{type: SeekVisitor}, {type: WaitAnswer}]}",
        )
    )
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0))
    assert bench.tick() == RUNNING
    bench.advance(119.9)  # site timeouts.answer is 120 s
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert bench.core.board.get(keys.DECLINED) == frozenset({7})
    assert bench.core.journal.incidents[-1].text == (
        "visitor 7 gave no answer within 120 s: seek again"
    )


def test_an_unanswered_approach_fails_after_the_site_timeout(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            "root: {type: Sequence, memory: true, children: ["
            "{type: SeekVisitor}, {type: ApproachVisitor}]}",
        )
    )
    bench.pose(0.0, 0.0)
    bench.persons((7, 2.0, 0.0, 180.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 7})]
    bench.advance(119.9)  # site timeouts.approach is 120 s
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert bench.core.journal.incidents[-1].kind == "approach failed"


def test_a_command_is_blamed_on_its_node_with_what_it_read(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            """
        root:
          type: Sequence
          memory: true
          children:
            - {type: SeekVisitor}
            - {type: ApproachVisitor}
    """,
        )
    )
    bench.pose(100.0, 30.0)
    bench.persons((2, 103.0, 30.0, 200.0))
    bench.tick()
    assert bench.take_published() == [("/ApproachPeopleFar", {"data": 2})]
    assert bench.core.blamed.startswith("ApproachVisitor (t.yaml:")
    assert bench.core.blamed_reads["/visitor"] == "2"  # what the deciding node read
