"""Abort guard, charging wait and stale inputs, ticked by hand."""

from __future__ import annotations

from bench import Bench, write_tree

from frog_bt.model import keys
from frog_bt.model.frontend import ContentDone, FrontendIdle, Tour, Volume
from frog_bt.model.ros import Diagnostics
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

GUARD = """
root:
  type: Sequence
  memory: true
  children:
    - {type: TourStatus, state: started}
    - type: Selector
      memory: false
      children:
        - type: Sequence
          memory: true
          children: [{type: MustAbort}, {type: TourStatus, state: aborted}, {type: ClearAbort}]
        - {type: WaitEvent, event: content_done, timeout: 600}
"""


def diagnostics(bench, battery=80.0, *faults):
    bench.ros("diagnostic", Diagnostics(bench.clock.now(), battery, tuple(faults)))


def test_low_battery_during_a_tour_aborts_with_the_reason(tmp_path):
    bench = Bench(write_tree(tmp_path, GUARD))
    diagnostics(bench, 50.0)
    assert bench.tick() == RUNNING
    diagnostics(bench, 19.5)
    assert bench.tick() == SUCCESS
    assert bench.take_sent() == [Tour("started", ""), Tour("aborted", "battery 20% below 20%")]


def test_stale_diagnostics_are_not_acted_on(tmp_path):
    bench = Bench(write_tree(tmp_path, GUARD))
    diagnostics(bench, 10.0, "motors: overheated")
    bench.advance(6.0)  # older than safety.diagnostics_max_age
    assert bench.tick() == RUNNING
    assert [m for m in bench.take_sent() if m.state == "aborted"] == []
    diagnostics(bench, 80.0, "motors: overheated")
    assert bench.tick() == SUCCESS
    assert bench.take_sent() == [Tour("aborted", "electronics fault: motors: overheated")]


def test_no_abort_outside_a_tour(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: MustAbort}"))
    diagnostics(bench, 5.0)
    assert bench.tick() == FAILURE


def test_a_tour_starts_only_when_charged_and_without_faults(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: WaitFrontendIdle}"))
    bench.event(FrontendIdle())
    diagnostics(bench, 25.0)
    assert bench.tick() == RUNNING
    assert bench.core.root.feedback_message == "charging: battery 25% < 30%"
    diagnostics(bench, 31.0, "lidar: stale")
    assert bench.tick() == RUNNING
    diagnostics(bench, 31.0)
    assert bench.tick() == SUCCESS


def test_missing_diagnostics_do_not_hold_a_tour_back(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: WaitFrontendIdle}"))
    bench.event(FrontendIdle())
    assert bench.tick() == SUCCESS


def test_location_features_pause_on_a_stale_pose(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            "root: {type: LocationAware, child: "
            "{type: WaitEvent, event: content_done, timeout: 600}}",
        )
    )
    bench.pose(95.9, 17.2)  # in the shop zone
    bench.tick()
    assert bench.take_sent() == [Volume(50)]
    bench.advance(3.0)  # no pose since: stale; the robot may have left the shop
    bench.tick()
    assert bench.take_sent() == []
    assert bench.core.root.feedback_message.startswith("pose stale")
    bench.pose(60.0, 60.0)
    bench.tick()
    assert bench.take_sent() == [Volume(100)]


def test_silent_face_stream_is_reported_and_gives_no_data(tmp_path):
    bench = Bench(
        write_tree(
            tmp_path,
            """
        root:
          type: FaceStream
          child:
            type: Sequence
            memory: true
            children:
              - {type: WaitEvent, event: content_done, timeout: 600}
              - {type: DecideEngagement, about: POI1}
        """,
        )
    )
    bench.tick()
    bench.advance(4.0)
    bench.tick()
    assert bench.core.root.feedback_message == "no face data for 4 s"
    bench.event(ContentDone("POI1", "a"))
    assert bench.tick() == SUCCESS
    about, decision = bench.core.board.get(keys.ENGAGEMENT_DECISION)
    assert (about, decision.engaged, decision.stored) == ("POI1", None, 0)
