"""FaceStream: samples stored only near and facing, the meter every 2 s, the decision."""

from __future__ import annotations

import pytest
from bench import Bench, write_tree

from frog_bt.model import keys
from frog_bt.model.frontend import ContentDone, Engagement, FinishPoi, StartPoi
from frog_bt.model.ros import Face, FaceData

TREE = """
root:
  type: FaceStream
  child:
    type: Sequence
    memory: true
    children:
      - {type: PlayContent, poi: POI1, part: a}
      - {type: DecideEngagement, about: POI1}
      - type: FailureIsSuccess
        child:
          type: Sequence
          memory: true
          children:
            - {type: Engaged}
            - {type: PlayContent, poi: POI1, part: b}
      - {type: FinishPoi, poi: POI1}
"""


def faces(bench, *levels_distance_facing):
    bench.ros(
        "faces",
        FaceData(
            bench.clock.now(),
            tuple(
                Face(7, level, distance, facing)
                for level, distance, facing in levels_distance_facing
            ),
        ),
    )


def run_part_a(bench, series):
    """Feed (dt, level, distance, facing) samples one per tick, then end part a."""
    bench.tick()
    for dt, level, distance, facing in series:
        bench.advance(dt)
        faces(bench, (level, distance, facing))
        bench.tick()
    bench.event(ContentDone("POI1", "a"))
    bench.tick()


def test_icl_on_for_the_scope_and_meter_every_two_seconds(tmp_path):
    bench = Bench(write_tree(tmp_path, TREE))
    series = [
        (0.5, 0.4, 1.0, True),
        (0.5, -0.6, 1.0, True),
        (0.5, 0.8, 1.0, True),
        (0.5, 0.9, 3.0, True),  # too far: not stored
        (0.5, -0.5, 1.0, True),
        (0.5, -0.7, 1.0, False),  # not facing: not stored
        (1.0, -0.9, 1.0, True),
    ]
    run_part_a(bench, series)
    sent = bench.take_sent()
    meters = [m.level for m in sent if isinstance(m, Engagement)]
    # window (0, 2]: 0.4, -0.6, 0.8 (0.9 far) -> engaged side mean 0.6
    # window (2, 4]: -0.5 (-0.7 not facing), -0.9 -> -0.7
    assert meters == [pytest.approx(0.6), pytest.approx(-0.7)]
    about, decision = bench.core.board.get(keys.ENGAGEMENT_DECISION)
    assert (about, decision.stored, decision.votes) == ("POI1", 5, 2)  # ceil(0.75) from each end
    # first (0.4) engaged, last (-0.9) not: a tie -> no extension by default
    assert decision.tie and decision.engaged is False
    assert StartPoi("POI1", "POI1", "b") not in sent
    assert sent[-1] == FinishPoi("POI1")
    assert bench.take_published() == [
        ("/ICL_command", {"data": "start"}),
        ("/ICL_command", {"data": "stop"}),
    ]


def test_engaged_visitor_gets_part_b(tmp_path):
    bench = Bench(write_tree(tmp_path, TREE))
    run_part_a(bench, [(0.1, 0.5, 1.0, True)] * 20)
    assert StartPoi("POI1", "POI1", "b") in bench.take_sent()
    bench.event(ContentDone("POI1", "b"))
    bench.tick()
    assert bench.take_sent()[-1] == FinishPoi("POI1")


def test_empty_window_sends_null_level(tmp_path):
    bench = Bench(write_tree(tmp_path, TREE))
    bench.tick()
    bench.advance(2.0)
    bench.tick()
    assert bench.take_sent()[-1] == Engagement(None)
