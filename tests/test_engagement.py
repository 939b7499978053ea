"""Engagement maths on hand-made sample series: meter windows and the 15% edge vote."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from frog_bt.maths.engagement import Samples, decide, edge_indices, mean, meter, qualifies
from frog_bt.model.ros import Face


def test_meter_is_the_mean_of_the_majority_side():
    assert meter([0.4, 0.6, -0.2]) == pytest.approx(0.5)
    assert meter([-0.4, -0.8, 0.9]) == pytest.approx(-0.6)


def test_meter_tie_is_the_mean_of_all_and_empty_is_none():
    assert meter([0.5, -0.3]) == pytest.approx(0.1)
    assert meter([]) is None


def test_zero_counts_as_engaged():
    assert meter([0.0, -0.5, 0.0]) == 0.0
    assert decide([0.0]).engaged is True


def test_windows_are_half_open_on_time():
    s = Samples()
    for t, v in [(0.0, -1.0), (0.5, 0.2), (2.0, 0.4), (2.1, -0.9), (3.9, -0.7), (4.0, -0.5)]:
        s.add(t, v)
    assert list(s.window(0.0, 2.0)) == [0.2, 0.4]  # (0, 2]
    assert list(s.window(2.0, 4.0)) == [-0.9, -0.7, -0.5]
    assert meter(s.window(2.0, 4.0)) == pytest.approx(-0.7)


@pytest.mark.parametrize(
    ("n", "expected"),
    [
        (0, []),
        (1, [0]),
        (2, [0, 1]),
        (7, [0, 1, 5, 6]),
        (10, [0, 1, 8, 9]),
        (20, [0, 1, 2, 17, 18, 19]),
        (100, [*range(15), *range(85, 100)]),
    ],
)
def test_edge_indices_take_ceil_15_percent_from_each_end(n, expected):
    assert list(edge_indices(n, 0.15)) == expected


def test_decision_ignores_the_middle_of_the_content():
    # engaged at the start and the end, bored in the middle: engaged
    levels = [0.5] * 3 + [-0.8] * 14 + [0.3] * 3
    d = decide(levels)
    assert (d.engaged, d.engaged_votes, d.votes, d.stored) == (True, 6, 6, 20)
    # the reverse: bored
    assert decide([-v for v in levels]).engaged is False


def test_tie_and_no_data():
    tie = [0.5] * 3 + [0.0] * 14 + [-0.5] * 3
    assert decide(tie, on_tie=False).engaged is False
    assert decide(tie, on_tie=True).engaged is True
    assert decide(tie).tie
    none = decide([])
    assert none.engaged is None and none.describe() == "no face data"


def test_only_near_and_facing_faces_qualify():
    assert qualifies(Face(1, 0.5, 1.9, True), near=2.0)
    assert qualifies(Face(1, 0.5, 2.0, True), near=2.0)
    assert not qualifies(Face(1, 0.5, 2.1, True), near=2.0)
    assert not qualifies(Face(1, 0.5, 1.0, False), near=2.0)


@given(st.lists(st.floats(-1, 1), max_size=300), st.floats(0.01, 0.5))
def test_decision_votes_are_consistent(levels, edge):
    d = decide(levels, edge)
    assert d.stored == len(levels)
    if levels:
        assert 1 <= d.votes <= len(levels)
        assert 0 <= d.engaged_votes <= d.votes
        assert d.engaged is (d.engaged_votes * 2 > d.votes) or d.tie


@given(st.lists(st.floats(-1, 1), min_size=1, max_size=700))
def test_the_mean_is_numpys_to_the_last_bit(levels):
    # the meter goes to the front end and into recordings: replays of tours recorded
    # when this maths used numpy must find the same doubles
    import numpy as np

    assert mean(levels) == float(np.mean(np.array(levels, dtype=float)))
    assert meter(levels) == float(np.clip(np.array(levels)[_side(levels)].mean(), -1, 1))


def _side(levels):
    engaged = sum(1 for v in levels if v >= 0.0)
    rest = len(levels) - engaged
    if engaged > rest:
        return [v >= 0.0 for v in levels]
    if rest > engaged:
        return [v < 0.0 for v in levels]
    return [True] * len(levels)
