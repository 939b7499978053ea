"""GoalLeaf, the base of Navigate, ApproachVisitor and Docking: a tiny subclass ticked by
hand on a ManualClock."""

from __future__ import annotations

from typing import ClassVar

import pytest
from bench import Bench, write_tree

from frog_bt.behaviours.goal_leaf import Failure, GoalLeaf, goal_state
from frog_bt.model import keys
from frog_bt.model.goals import Goal
from frog_bt.tree.factory import NodeFactory
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Params


class Fetch(GoalLeaf):
    """Drive to POI3; what happened goes to ``ended`` (a test's own list)."""

    class Params(Params):
        timeout: float | None = None

    reads = (keys.NOW, keys.GOAL)
    ended: ClassVar[list[Failure | str]] = []
    holding: ClassVar[str | None] = None

    def default_timeout(self) -> float:
        return 10.0

    def hold(self) -> str | None:
        return self.holding

    def send(self) -> Goal:
        return self.ctx.actions.goto("POI3", self.ctx.site.pois["POI3"])

    def succeeded(self) -> None:
        self.ended.append("succeeded")

    def failed(self, why: Failure) -> None:
        self.ended.append(why)

    def progress(self) -> str:
        assert self.latest is not None
        return self.latest.state()


class PausedFetch(Fetch):
    """Fetch that waits while the operator pauses."""

    optional_reads = (keys.PAUSED, keys.POSE)
    waits_while_paused = True


@pytest.fixture
def bench(tmp_path, request):
    Fetch.ended = []
    Fetch.holding = None
    kind = getattr(request, "param", "Fetch")
    tree = NodeFactory([Fetch, PausedFetch]).load(write_tree(tmp_path, f"root: {{type: {kind}}}"))
    return Bench(tree)


def leaf(bench) -> GoalLeaf:
    (node,) = (n for n in bench.core.root.iterate() if isinstance(n, GoalLeaf))
    return node


def sent(bench) -> list[str]:
    return [topic for topic, _ in bench.take_published()]


def test_sends_on_start_and_succeeds_on_response_2(bench):
    bench.at("POI3")
    assert bench.tick() == RUNNING
    assert sent(bench) == ["/GotoWayPoint"]
    bench.ros("response", 1)
    assert bench.tick() == RUNNING
    assert leaf(bench).feedback_message == "active"
    bench.ros("response", 2)
    assert bench.tick() == SUCCESS
    assert Fetch.ended == ["succeeded"]
    assert sent(bench) == []


@pytest.mark.parametrize("code", [3, 4])
def test_fails_when_the_robot_refuses(bench, code):
    bench.tick()
    bench.ros("response", code)
    assert bench.tick() == FAILURE
    assert Fetch.ended == [Failure.REFUSED]


def test_times_out_on_the_project_clock_from_the_send(bench):
    Fetch.holding = "not yet"
    bench.tick()
    bench.advance(5.0)
    Fetch.holding = None
    bench.tick()
    assert sent(bench) == ["/GotoWayPoint"]
    bench.advance(9.9)
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert Fetch.ended == [Failure.TIMED_OUT]
    assert bench.core.actions.pending is None  # cancelled: a late answer is stale


def test_a_newer_goal_replaces_it(bench):
    bench.tick()
    site = bench.site
    bench.core.actions.goto("POI1a", site.pois["POI1a"])  # someone else's goal
    assert bench.tick() == FAILURE
    assert Fetch.ended == [Failure.REPLACED]
    assert bench.core.actions.pending is not None  # the newer goal still waits


def test_halted_while_pending_stops_waiting_and_a_late_answer_is_stale(bench):
    bench.tick()
    bench.core.halt()
    assert leaf(bench).status == INVALID
    assert bench.core.actions.pending is None
    bench.core.halt()  # terminate twice: nothing more
    bench.ros("response", 2)
    bench.tick()  # starts again: a new goal, the old answer counted stale
    assert bench.core.actions.stale_responses == 1
    assert sent(bench) == ["/GotoWayPoint", "/GotoWayPoint"]
    assert Fetch.ended == []


def test_held_sends_nothing_until_the_hold_ends_and_a_halt_cancels_nothing(bench):
    Fetch.holding = "the door is shut"
    assert bench.tick(3) == RUNNING
    assert sent(bench) == []
    assert leaf(bench).feedback_message == "the door is shut"
    bench.core.halt()
    assert bench.core.actions.pending is None and Fetch.ended == []
    Fetch.holding = None
    bench.tick()
    assert sent(bench) == ["/GotoWayPoint"]


@pytest.mark.parametrize("bench", ["PausedFetch"], indirect=True)
def test_the_operators_pause_holds_the_send_of_a_leaf_that_waits(bench):
    bench.core.board.set(keys.PAUSED, True)
    assert bench.tick() == RUNNING
    assert sent(bench) == []
    assert leaf(bench).feedback_message == "paused: PausedFetch waits"
    bench.advance(30.0)  # longer than the timeout: it runs from the send
    bench.core.board.set(keys.PAUSED, False)
    assert bench.tick() == RUNNING
    assert sent(bench) == ["/GotoWayPoint"]
    bench.pose(100.0, 30.0)
    bench.core.board.set(keys.PAUSED, True)  # a pause while the goal is out: stop now
    assert bench.tick() == RUNNING
    stop = bench.take_published()[-1]
    assert stop[0] == "/GotoWayPoint"
    assert stop[1]["pose"]["position"]["x"] == 100.0  # a goal where the robot is
    bench.pose(100.0, 30.0)  # the robot stands where it stopped
    bench.ros("response", 2)  # that answers the stop, not the leaf
    assert bench.tick() == RUNNING
    bench.core.board.set(keys.PAUSED, False)  # resume: the goal again
    assert bench.tick() == RUNNING
    assert bench.take_published()[-1][1]["pose"]["position"]["x"] != 100.0
    bench.at("POI3")
    bench.ros("response", 2)
    assert bench.tick() == SUCCESS


def test_the_pause_does_not_hold_a_leaf_that_does_not_wait(bench):
    bench.core.board.set(keys.PAUSED, True)
    bench.tick()
    assert sent(bench) == ["/GotoWayPoint"]


def test_a_subclass_must_declare_what_the_base_reads():
    with pytest.raises(TypeError, match="Blind reads /goal without declaring it"):
        type("Blind", (GoalLeaf,), {"reads": (keys.NOW,)})
    with pytest.raises(TypeError, match="Deaf reads /paused, /pose without declaring it"):
        type("Deaf", (GoalLeaf,), {"reads": (keys.NOW, keys.GOAL), "waits_while_paused": True})


def test_goal_state_follows_the_sent_goal_by_id():
    sent_goal = Goal(2, "goto", "POI3", 0.0, 0)
    assert goal_state(sent_goal, None) is sent_goal
    assert goal_state(sent_goal, Goal(1, "goto", "POI1a", 0.0, 0)) is sent_goal  # same tick
    answered = Goal(2, "goto", "POI3", 0.0, 0, answered_at=1.0)
    assert goal_state(sent_goal, answered) is answered
    assert goal_state(sent_goal, Goal(3, "goto", "POI1a", 0.0, 0)) is None
