"""The taps, ticked by hand (tests/bench.py): what is buffered, stamped with which tick."""

from __future__ import annotations

from pathlib import Path

import py_trees
import pytest
from bench import Bench, write_tree

from frog_bt.live.telemetry import Telemetry
from frog_bt.live.telemetry.layout import TreeIndex
from frog_bt.live.telemetry.rows import CODES, Rows
from frog_bt.model.frontend import FrontendIdle
from frog_bt.model.outcomes import IncidentKind, Level
from frog_bt.runtime.observer import attach_all

S = py_trees.common.Status
TREE = """
root:
  type: Sequence
  name: Top
  memory: true
  children:
    - {type: WaitFrontendIdle, name: Wait}
    - {type: Navigate, poi: POI0}
    - {type: TourStatus, state: started}
"""


@pytest.fixture
def bench(tmp_path: Path) -> Bench:
    return Bench(write_tree(tmp_path, TREE))


def rows_on(bench: Bench, **kwargs: object) -> Rows:
    rows = Rows(bench.site, TreeIndex.of(bench.core.tree.root), **kwargs)  # type: ignore[arg-type]
    bench.observers.attach(bench, [rows])  # type: ignore[list-item]
    return rows


def test_rows_belong_to_the_tick_that_consumes_or_produces_them(bench: Bench):
    run, invalid = CODES[S.RUNNING], CODES[S.INVALID]
    rows = rows_on(bench)
    t0 = bench.clock.now()
    bench.pose(1.0, 2.0)
    assert rows.batch.poses == [(1, t0, 1.0, 2.0, 0.0)]  # consumed by tick 1
    bench.tick()
    # the first row has every node, later ones only the nodes whose status changed
    first = ((0, run), (1, run), (2, invalid), (3, invalid))  # as codes: CODES[status]
    assert rows.batch.statuses == [(1, t0, first)]
    bench.advance(0.1)
    bench.tick()
    assert len(rows.batch.statuses) == 1  # nothing changed: nothing recorded
    bench.event(FrontendIdle())
    bench.advance(0.1)
    bench.tick()  # tick 3: the front end is ready, the goal goes out
    t3 = bench.clock.now()
    assert rows.batch.statuses[-1] == (3, t3, ((1, CODES[S.SUCCESS]), (2, run)))
    assert rows.batch.events == [(3, t0 + 0.1, "frontend_idle", FrontendIdle())]
    [(tick, t, side, topic, _)] = rows.batch.outputs
    assert (tick, t, side, topic) == (3, t3, "ros", bench.site.topic("goto"))
    assert rows.batch.notes == [(3, t3, "go to POI0", Level.INFO)]
    bench.ros("response", 2)
    assert rows.batch.inputs[-1][:3] == (4, t3, "response")
    batch = rows.drain()
    assert len(batch) == 8 and len(rows.batch) == 0  # /target among them (a stop lane)


def test_notes_are_taken_once_even_when_the_list_is_trimmed(bench: Bench):
    rows = rows_on(bench)
    ctx = bench.core.ctx
    bench.core.journal.limit = 4
    ctx.note("a")
    bench.tick()
    for text in "bcdef":
        ctx.note(text)
    bench.tick()
    ctx.note("g")
    bench.tick()
    # "b" was trimmed before any tick saw it; nothing is taken twice
    assert [note[2] for note in rows.batch.notes] == ["a", "c", "d", "e", "f", "g"]


def test_a_notes_level_comes_from_its_incident_kind_not_its_words(bench: Bench):
    rows = rows_on(bench)
    journal = bench.core.journal
    journal.note("the visitor's umbrella failed to open")  # words of failure, no incident
    journal.note("approach of visitor 7 timed out", IncidentKind.APPROACH_FAILED)
    journal.note("resuming the tour at POI2", IncidentKind.RESUMED)
    journal.note("giving up: undock failed", IncidentKind.GAVE_UP)
    bench.tick()
    assert [(note[2][:9], note[3]) for note in rows.batch.notes] == [
        ("the visit", Level.INFO),
        ("approach ", Level.WARN),
        ("resuming ", Level.INFO),
        ("giving up", Level.ERROR),
    ]


def test_rows_ask_to_be_written_every_batch_ticks_and_stop_after_detach(bench: Bench):
    calls: list[int] = []
    rows = rows_on(bench, batch_ticks=3, on_full=lambda: calls.append(bench.core.ticks))
    for _ in range(7):
        bench.tick()
        if calls and calls[-1] == bench.core.ticks:
            rows.drain()
    assert calls == [3, 6]
    rows.detach()
    assert rows.core is None
    bench.pose(0.0, 0.0)
    bench.tick()
    assert rows.batch.poses == [] and rows.batch.statuses == []


def test_telemetry_over_a_core_ticked_by_hand(bench: Bench, tmp_path: Path):
    from rerun.chunk import RrdReader

    path = tmp_path / "hand.rrd"
    telemetry = Telemetry.open(f"save:{path}", bench.site, bench.core.tree)
    attach_all(bench, [telemetry])
    bench.pose(104.0, 32.0)
    bench.tick(2)
    bench.event(FrontendIdle())
    bench.advance(0.1)
    bench.tick()  # goal sent
    bench.advance(1.0)
    bench.ros("response", 2)
    bench.tick()  # arrived: the goal is cleared, in the same batch
    telemetry.close()
    telemetry.close()
    goal: dict[str, list[int]] = {}
    notes: list[str] = []
    for chunk in RrdReader(path).stream():
        batch = chunk.to_record_batch()
        if chunk.entity_path == "/map/goal":
            kind = "clear" if "Clear:is_recursive" in batch.schema.names else "shown"
            goal.setdefault(kind, []).extend(batch.column("tick").to_pylist())
        if chunk.entity_path == "/log/notes":
            notes += [t[0] for t in batch.column("TextLog:text").to_pylist()]
        assert "log_time" not in batch.schema.names  # only tick and time
    assert goal == {"shown": [3], "clear": [4]}
    assert notes == ["go to POI0", "arrived at POI0", "tour started"]


def test_rows_before_the_clock_has_a_time_take_the_first_ticks_time(tmp_path: Path):
    from frog_bt.clock import SimClock

    bench = Bench(write_tree(tmp_path, TREE))
    clock = SimClock()
    bench.core.clock = clock
    rows = rows_on(bench)
    bench.event(FrontendIdle())  # before the first /clock
    assert rows.batch.events[0][0] == 1
    clock.set(1000.0)
    bench.core.tick()
    assert rows.batch.events == [(1, 1000.0, "frontend_idle", FrontendIdle())]
    assert rows.batch.statuses[0][:2] == (1, 1000.0)


def test_rows_that_never_got_a_time_are_dropped(tmp_path: Path):
    from frog_bt.clock import SimClock

    bench = Bench(write_tree(tmp_path, TREE))
    bench.core.clock = SimClock()
    rows = rows_on(bench)
    bench.pose(1.0, 2.0)
    assert len(rows.batch.poses) == 1
    assert len(rows.drain()) == 0


def test_a_stop_given_up_within_one_tick_still_reaches_its_lane(bench: Bench):
    """/skipped is written and cleared (the next stop's scope) inside one tick, so the
    end-of-tick blackboard never shows it: the stop's lane reads the journal's incidents."""
    rows = rows_on(bench)
    bench.tick()
    bench.core.journal.note(
        "skipped POI2: navigation kept failing", IncidentKind.STOP_SKIPPED, subject="POI2"
    )
    bench.core.journal.note("skipped POI3: the operator asked", IncidentKind.STOP_LEFT, "POI3")
    bench.core.journal.note("arrived at POI0")
    bench.tick()
    left = [row for row in rows.batch.blackboard if row[2] == "/skipped"]
    assert [(tick, poi) for tick, _, _, poi in left] == [(2, "POI2"), (2, "POI3")]
    bench.tick()
    assert len([row for row in rows.batch.blackboard if row[2] == "/skipped"]) == 2  # once
