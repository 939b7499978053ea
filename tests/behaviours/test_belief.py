"""Believe only what fits: answers matched to the goal they answer, by order and by pose.

``/FROG_response`` carries no goal id; a core ticked by hand on a ManualClock, fed the
robot's answers and poses in the orders a real link can deliver them."""

from __future__ import annotations

from bench import Bench, write_tree

from frog_bt.engine.belief import Verdict, World, describe_answer, judge
from frog_bt.model import keys
from frog_bt.model.events import Doubted
from frog_bt.model.goals import Goal
from frog_bt.model.key import Reading
from frog_bt.model.outcomes import TourState
from frog_bt.model.ros import Diagnostics, PersonDetection, PersonDetections, Point, Pose
from frog_bt.runtime.observer import listen
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

NAVIGATE_POI2 = "root: {type: Navigate, poi: POI2}"
# A stop, and the abort that sends the robot home: the tour tree's shape, in small
ABORT_HOME = """
root:
  type: Selector
  memory: false
  children:
    - type: Sequence
      memory: true
      children: [{type: MustAbort}, {type: Navigate, poi: SHOP}]
    - {type: Navigate, poi: POI2}
"""


def doubts(bench: Bench) -> list[Doubted]:
    seen: list[Doubted] = []
    listen(bench, seen.append, Doubted)
    return seen


def reach_poi2_as_a_fault_comes(tmp_path) -> tuple[Bench, list[Doubted]]:
    """The stop's goal out and active, the robot at POI2 and a fault: the next tick
    aborts and sends the drive home while the stop's goal is still open."""
    bench = Bench(write_tree(tmp_path, ABORT_HOME))
    seen = doubts(bench)
    bench.core.board.set(keys.TOUR_STATE, TourState.STARTED)
    bench.ros("diagnostic", Diagnostics(bench.clock.now(), 80.0, ()))
    bench.tick()
    bench.ros("response", 1)
    bench.at("POI2a")
    bench.tick()
    bench.ros("diagnostic", Diagnostics(bench.clock.now(), 12.0, ()))  # battery low
    assert bench.tick() == RUNNING
    home = bench.core.actions.pending
    assert home is not None and home.target == "SHOP"
    return bench, seen


def test_a_stops_late_arrival_after_the_drive_home_is_not_its_answer(tmp_path):
    bench, seen = reach_poi2_as_a_fault_comes(tmp_path)
    home = bench.core.actions.pending
    bench.ros("response", 2)  # POI2's arrival, on its way when the drive home went out
    assert bench.tick() == RUNNING
    assert bench.core.actions.pending == home  # still waiting for SHOP
    assert [d.why for d in seen] == ["arrival at POI2a heard after the drive to SHOP: ignored"]
    assert seen[0].answers == "POI2a" and seen[0].goal == "SHOP"
    assert bench.core.journal.notes[-1].text == seen[0].why  # the decision log says so
    # the robot takes the new goal, drives and arrives: that answer is believed
    bench.ros("response", 1)
    bench.at("SHOP")
    bench.ros("response", 2)
    assert bench.tick() == SUCCESS
    assert len(seen) == 1


def test_a_stale_arrival_with_a_pose_between_is_still_caught_by_the_pose(tmp_path):
    bench, seen = reach_poi2_as_a_fault_comes(tmp_path)
    home = bench.core.actions.pending
    bench.at("POI2a")  # a pose arrives before the late answer: order alone would believe it
    bench.ros("response", 2)
    assert bench.tick() == RUNNING
    assert bench.core.actions.pending == home
    assert [d.why for d in seen] == ["arrival at POI2a heard after the drive to SHOP: ignored"]


def test_a_stale_failure_does_not_fail_the_new_goal(tmp_path):
    bench, seen = reach_poi2_as_a_fault_comes(tmp_path)
    home = bench.core.actions.pending
    bench.ros("response", 4)  # the stop's goal aborted as it was replaced
    assert bench.tick() == RUNNING
    assert bench.core.actions.pending == home
    assert seen[0].why == "abort of the drive to POI2a heard after the drive to SHOP: ignored"


def test_an_arrival_far_from_the_goal_is_doubted_and_the_goal_waits_on(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE_POI2))
    seen = doubts(bench)
    assert bench.tick() == RUNNING
    bench.ros("response", 1)
    bench.at("POI1a")  # 25 m short of POI2a
    bench.ros("response", 2)
    assert bench.tick() == RUNNING
    assert [d.why for d in seen] == ["arrival at POI2a heard 26 m from it: not believed"]
    bench.at("POI2a")  # the next answer decides
    bench.ros("response", 2)
    assert bench.tick() == SUCCESS


def test_an_arrival_with_no_pose_is_not_believed_and_the_timeout_decides(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: Navigate, poi: POI2, timeout: 30}"))
    seen = doubts(bench)
    bench.tick()
    bench.ros("response", 2)
    assert bench.tick() == RUNNING
    assert seen[0].why == "arrival at POI2a heard with no pose yet: not believed"
    bench.advance(30)
    assert bench.tick() == FAILURE


def test_an_arrival_heard_just_before_the_pose_that_shows_it_is_believed(tmp_path):
    # a robot may publish "arrived" before its last pose: within navigation.pose_grace
    bench = Bench(write_tree(tmp_path, NAVIGATE_POI2))
    seen = doubts(bench)
    bench.tick()
    bench.ros("response", 1)
    bench.at("POI1a")
    bench.ros("response", 2)
    assert bench.tick() == RUNNING
    assert seen[0].why == "arrival at POI2a heard 26 m from it: not believed"
    bench.advance(1.5)
    bench.at("POI2a")
    assert bench.tick() == SUCCESS


def test_a_pose_that_shows_the_arrival_too_late_does_not_confirm_it(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE_POI2))
    bench.tick()
    bench.ros("response", 1)
    bench.at("POI1a")
    bench.ros("response", 2)
    bench.tick()
    bench.advance(2.5)  # past navigation.pose_grace (2 s)
    bench.at("POI2a")
    assert bench.tick() == RUNNING
    assert bench.core.actions.unconfirmed is None


def test_an_immediate_refusal_of_a_first_goal_is_believed(tmp_path):
    # nothing open before it: a 4 at once is this goal's refusal (a robot on its charger)
    bench = Bench(write_tree(tmp_path, NAVIGATE_POI2))
    bench.tick()
    bench.ros("response", 4)
    assert bench.tick() == FAILURE


def approach_goal(visitor: int = 7) -> Goal:
    return Goal(1, "approach", str(visitor), 0.0, visitor)


def world(persons: tuple[int, ...], age: float = 0.0) -> World:
    seen = PersonDetections(0.0, tuple(PersonDetection(p, Point(0.0, 0.0), 180.0) for p in persons))
    return World(
        now=10.0,
        pose=Reading(Pose(0.0, "map", 0.0, 0.0, 0.0, 1.0), 10.0),
        persons=Reading(seen, 10.0 - age),
        poses_at_answer=1,
        tolerance=2.0,
        detection_max_age=1.0,
    )


def test_an_approach_success_is_believed_only_while_the_visitor_is_seen():
    assert judge(approach_goal(), 2, world((7, 3)), None).verdict is Verdict.BELIEVED
    gone = judge(approach_goal(), 2, world((3,)), None)
    assert gone.verdict is Verdict.DOUBTED
    assert gone.why == "approach of visitor 7 succeeded, but they are not seen: not believed"
    stale_view = judge(approach_goal(), 2, world((7,), age=5.0), None)
    assert stale_view.verdict is Verdict.DOUBTED
    assert judge(approach_goal(), 3, world(()), None).verdict is Verdict.BELIEVED


def test_answers_in_domain_terms():
    home = Goal(2, "goto", "SHOP", 0.0, Pose(0.0, "map", 0.0, 0.0, 0.0, 1.0))
    assert describe_answer(2, home) == "arrival at SHOP"
    assert describe_answer(3, home) == "failure of the drive to SHOP"
    assert describe_answer(4, approach_goal()) == "refusal of the approach of visitor 7"


def test_what_actions_hold_is_given_back_whole(tmp_path):
    bench = Bench(write_tree(tmp_path, NAVIGATE_POI2))
    bench.tick()
    actions = bench.core.actions
    held = actions.snapshot()
    first = actions.pending
    second = actions.goto("SHOP", bench.site.pois["SHOP"])
    assert actions.pending == second and actions.before == first
    actions.restore(held)
    assert actions.pending == first and actions.before is None
    again = actions.goto("SHOP", bench.site.pois["SHOP"])
    assert again.id == second.id  # the ids go on from where they were held
