"""The one count of tours (frog_bt/model/ledger.py), on hand-made event streams: what
reached, played and skipped mean, and (hypothesis) that no stream of events makes a
stop both skipped and reached, or played without being reached."""

from __future__ import annotations

import json
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from frog_bt.model.channels import Alert
from frog_bt.model.events import (
    AlertChanged,
    Doubted,
    Event,
    FrontendIn,
    FrontendOut,
    OperatorDone,
    RobotCommand,
    RobotInput,
)
from frog_bt.model.frontend import (
    AskTour,
    ContentDone,
    FinishPoi,
    StartPoi,
    Tour,
    UserPositive,
)
from frog_bt.model.goals import Goal
from frog_bt.model.ledger import fold
from frog_bt.model.outcomes import TourState
from frog_bt.model.ros import Pose
from frog_bt.model.tours import Fate, SkipWhy, TourPlan, TourRow

STOPS = ("POI1", "POI2", "POI3")
PLAN = TourPlan(
    stops=(*STOPS, "TEMP"),
    content=STOPS,
    waypoints={"POI1": "POI1", "POI1b": "POI1", "POI2": "POI2", "POI3": "POI3", "TEMP": "TEMP"},
    topics={"response": "/FROG_response", "docking_state": "/docking/state", "pose": "/pose"},
)
HERE = Pose(0.0, "map", 0.0, 0.0, 0.0, 1.0)


class Script:
    """Events in order, each a second after the one before."""

    def __init__(self) -> None:
        self.t = 0.0
        self.events: list[Event] = []

    def _next(self) -> float:
        self.t += 1.0
        return self.t

    def out(self, message: Any) -> Script:
        self.events.append(FrontendOut(self._next(), message))
        return self

    def into(self, message: Any) -> Script:
        self.events.append(FrontendIn(self._next(), message))
        return self

    def tour(self, state: str, reason: str = "") -> Script:
        return self.out(Tour(TourState(state), reason))

    def goto(self, target: str) -> Script:
        t = self._next()
        goal = Goal(1, "goto", target, t, HERE)
        self.events.append(RobotCommand(t, "goto", "/GotoWayPoint", HERE, {}, goal))
        return self

    def answer(self, code: int) -> Script:
        self.events.append(RobotInput(self._next(), "/FROG_response", code))
        return self

    def approach(self, person: int) -> Script:
        t = self._next()
        self.events.append(RobotCommand(t, "approach", "/ApproachPeopleFar", person, {}))
        return self

    def recruit(self, person: int = 7) -> Script:
        return self.approach(person).answer(2).out(AskTour(True)).into(UserPositive())

    def play(self, poi: str, waypoint: str = "") -> Script:
        return (
            self.out(StartPoi(poi, waypoint or poi, "a"))
            .into(ContentDone(poi, "a"))
            .out(FinishPoi(poi))
        )

    def visit(self, poi: str) -> Script:
        return self.goto(poi).answer(2).play(poi)

    def skip(self) -> Script:
        self.events.append(OperatorDone(self._next(), 1, "skip", True, "skipping", by="console"))
        return self

    def docked(self) -> Script:
        self.events.append(RobotInput(self._next(), "/docking/state", "docked"))
        return self


def test_a_whole_tour_reaches_and_plays_every_stop() -> None:
    s = Script().tour("started").recruit()
    for poi in STOPS:
        s.visit(poi)
    s.goto("TEMP").answer(2).goto("DOCK").answer(2).tour("ended")
    ledger = fold(PLAN, s.events)
    (row,) = ledger.tours
    assert row.reached == row.played == list(STOPS)  # TEMP has no content: not counted
    assert row.skips(PLAN.content) == []
    assert (row.ended, row.visitors, row.goals) == ("ended", [7], 5)
    assert (ledger.started, ledger.completed, ledger.aborted, ledger.said_yes) == (1, 1, 0, 1)


def test_a_stop_skipped_during_its_content_is_neither_reached_nor_played() -> None:
    """Tour 10 of the seeded season: "6 of 6" stops, and also "Skipped POI3 (operator)"."""
    s = Script().tour("started").recruit().visit("POI1").visit("POI2")
    s.goto("POI3").answer(2).out(StartPoi("POI3", "POI3", "a")).skip().out(FinishPoi("POI3"))
    s.goto("DOCK").answer(2).tour("ended")
    (row,) = fold(PLAN, s.events).tours
    assert [v.fate for v in row.stops] == [Fate.PLAYED, Fate.PLAYED, Fate.SKIPPED]
    assert row.reached == row.played == ["POI1", "POI2"]
    assert row.skips(PLAN.content) == [("POI3", SkipWhy.OPERATOR)]
    assert row.commands[0].command == "skip" and row.commands[0].by == "console"


def test_a_stop_skipped_on_the_way_and_one_given_up() -> None:
    s = Script().tour("started").recruit()
    s.goto("POI1").answer(3).goto("POI1").answer(4)  # given up after two failures
    s.goto("POI2").skip()  # skipped on the way
    s.visit("POI3").goto("DOCK").answer(2).tour("ended")
    (row,) = fold(PLAN, s.events).tours
    assert row.skips(PLAN.content) == [
        ("POI1", SkipWhy.NAVIGATION),
        ("POI2", SkipWhy.OPERATOR),
    ]
    assert row.reached == ["POI3"] and row.nav_retries == 1
    assert row.failed_goals == ["POI1", "POI1"]


def test_a_lost_visitor_leaves_the_stop_and_the_next_visitor_reaches_it() -> None:
    s = Script().tour("started").recruit(7).visit("POI1")
    s.goto("POI2").goto("POI0").recruit(8)  # the visitor left on the way
    s.visit("POI1").visit("POI2").visit("POI3").goto("DOCK").answer(2).tour("ended")
    (row,) = fold(PLAN, s.events).tours
    assert row.stops[1].skipped is SkipWhy.VISITOR_LOST
    assert row.reached == ["POI1", "POI1", "POI2", "POI3"]  # each visitor's visits
    assert row.skips(PLAN.content) == []  # POI2 was reached in the end
    assert row.visitors == [7, 8]


def test_an_arrival_not_believed_is_not_a_reach() -> None:
    s = Script().tour("started").recruit().goto("POI1").answer(2)
    s.events.append(Doubted(s._next(), 2, "POI1", "arrival 40 m from POI1: doubted"))
    (row,) = fold(PLAN, s.events).tours
    assert row.stops[0].fate is Fate.UNDER_WAY and row.reached == [] and row.doubted == 1
    s.answer(2)  # the next answer is believed
    (row,) = fold(PLAN, s.events).tours
    assert row.reached == ["POI1"] and row.played == []


def test_an_aborted_tour_keeps_its_drive_home_and_its_help() -> None:
    s = Script().tour("started").recruit().visit("POI1").goto("POI2")
    s.tour("aborted", "battery 12% below 15%").goto("DOCK").answer(2)
    raised = Alert("a1", "dock", "could not dock", "raised", s.t, answers=("done_by_hand",))
    s.events.append(AlertChanged(s._next(), raised))
    s.docked().goto("POI1")  # after the dock: no tour's
    ledger = fold(PLAN, s.events)
    (row,) = ledger.tours
    assert (row.ended, row.reason, row.goals, row.help) == (
        "aborted",
        "battery 12% below 15%",
        3,
        ["dock"],
    )
    assert row.skips(PLAN.content) == []  # aborted on the way to POI2: nothing skipped
    assert (ledger.completed, ledger.aborted) == (0, 1)


def test_a_fold_begun_inside_a_tour_counts_it_and_an_idle_opening_is_no_tour() -> None:
    s = Script().visit("POI2").visit("POI3").goto("DOCK").answer(2).tour("ended")
    (row,) = fold(PLAN, s.events).tours
    assert row.started is None and row.reached == ["POI2", "POI3"]
    idle = Script().docked().tour("started").recruit().tour("aborted", "operator").docked()
    ledger = fold(PLAN, idle.events)
    assert [r.started for r in ledger.tours] == [2.0] and ledger.started == 1


def test_a_resent_start_is_the_same_tour() -> None:
    s = Script().tour("started").recruit().tour("started").visit("POI1").tour("ended")
    ledger = fold(PLAN, s.events)
    assert len(ledger.tours) == 1 and ledger.tours[0].reached == ["POI1"]


def test_a_resumed_tour_carries_on_the_row_its_checkpoint_kept() -> None:
    """A restart: the first executive's row (as the checkpoint keeps it, through JSON) is
    carried on by the resumed executive's fold, once, as the report joins the files."""
    before = Script().tour("started").recruit().visit("POI1")
    before.goto("POI2").answer(2).out(StartPoi("POI2", "POI2", "a")).skip()
    before.goto("POI3")  # under way when the checkpoint was written: made again after
    first = fold(PLAN, before.events)
    assert first.current is not None
    kept = TourRow.of_json(json.loads(json.dumps(first.current.to_json())))
    assert kept == first.current
    after = Script()
    after.t = before.t
    after.goto("POI3").answer(2)  # what the resumed executive saw before the take-up
    ledger = fold(PLAN, after.events)
    ledger.resume(kept)
    ledger.resume(kept)  # once
    for event in after.play("POI3").goto("DOCK").answer(2).tour("ended").events[2:]:
        ledger.feed(event)
    (row,) = ledger.tours
    assert row.started == 1.0 and row.ended == "ended" and ledger.started == 1
    assert row.reached == row.played == ["POI1", "POI3"]
    assert row.skips(PLAN.content) == [("POI2", SkipWhy.OPERATOR)]
    assert [c.command for c in row.commands] == ["skip"]
    assert (row.accepted, ledger.said_yes, row.visitors) == (1, 1, [7])
    # nothing kept, or a fold that saw a tour start: nothing to carry on
    assert TourRow.of_json({"stops": [{"poi": 3}]}) is None
    fresh = fold(PLAN, Script().tour("started").events)
    fresh.resume(kept)
    assert fresh.tours[0].reached == [] and fresh.tours[0].commands == []


# ------------------------------------------------------------ any stream of events

STEPS = st.sampled_from(
    [
        ("tour", "started"),
        ("tour", "ended"),
        ("tour", "aborted"),
        *(("goto", w) for w in (*PLAN.waypoints, "DOCK")),
        ("answer", 2),
        ("answer", 3),
        ("doubt", 2),
        *(("start", poi) for poi in STOPS),
        *(("part_b", poi) for poi in STOPS),
        *(("done", poi) for poi in STOPS),
        *(("finish", poi) for poi in STOPS),
        ("skip", True),
        ("approach", 1),
        ("ask", True),
        ("docked", True),
    ]
)


def _script(steps: list[tuple[str, Any]]) -> list[Event]:
    s = Script()
    for kind, arg in steps:
        if kind == "tour":
            s.tour(arg)
        elif kind == "goto":
            s.goto(arg)
        elif kind == "answer":
            s.answer(arg)
        elif kind == "doubt":
            s.events.append(Doubted(s._next(), arg, "POI1", "doubted"))
        elif kind == "start":
            s.out(StartPoi(arg, arg, "a"))
        elif kind == "part_b":
            s.out(StartPoi(arg, arg, "b"))
        elif kind == "done":
            s.into(ContentDone(arg, "a"))
        elif kind == "finish":
            s.out(FinishPoi(arg))
        elif kind == "skip":
            s.skip()
        elif kind == "approach":
            s.approach(arg)
        elif kind == "ask":
            s.out(AskTour(None))
        else:
            s.docked()
    return s.events


@settings(max_examples=300, deadline=None)
@given(st.lists(STEPS, max_size=60))
def test_no_stream_makes_a_stop_both_skipped_and_reached(steps) -> None:
    ledger = fold(PLAN, _script(steps))
    for row in ledger.tours:
        for v in row.stops:
            assert not (v.played and not v.reached)  # played is a part of reached
            assert not (v.skipped is not None and (v.reached or v.played))
            assert v.poi in PLAN.content
        skipped = row.skips(PLAN.content)
        reached = set(row.reached)
        assert reached.isdisjoint(poi for poi, _ in skipped)
        assert len(reached) + len(skipped) <= len(PLAN.content)  # "N of M" adds up
        assert set(row.played) <= reached
    assert ledger.completed + ledger.aborted <= len(ledger.rows)


def test_stops_never_visited_are_listed_but_not_counted_as_left() -> None:
    s = Script().tour("started").recruit().goto("SHOP").answer(2).tour("ended")
    ledger = fold(PLAN, s.events)
    (row,) = ledger.tours
    assert row.skips(PLAN.content) == [(poi, SkipWhy.NOT_VISITED) for poi in STOPS]
    assert row.left(PLAN.content) == [] and ledger.skipped() == 0
