"""Figures shown to their precision, and the intervals behind them (no recordings)."""

from __future__ import annotations

import pytest

from frog_bt.offline.report.headline import rate
from frog_bt.offline.report.intervals import (
    between,
    change,
    difference,
    mean,
    measured,
    median,
    poisson,
    proportion,
    share,
    wilson,
)
from frog_bt.offline.report.precision import estimate, measure, places, with_interval


def test_a_rate_is_shown_to_its_interval_not_to_a_fixed_decimal() -> None:
    # 200 tours: an interval of about 11 points, whole points
    assert rate(wilson(152, 200)) == "76 % (152 of 200; 70 % to 81 %)"
    # 20,000: a tenth of a point
    assert rate(wilson(15200, 20000)).startswith("76.0 % (15200 of 20000; 75.4 % to 76.6 %)")
    assert rate(wilson(0, 0)) == "\u2013"


def test_tours_per_hour_and_interventions_are_shown_to_their_poisson_interval() -> None:
    per_hour = poisson(200, 70.0)  # a season: 2.857 tours an hour
    assert estimate(per_hour) == "2.9" and places(per_hour) == 1
    assert with_interval(per_hour) == "2.9 (95 %: 2.5 to 3.3)"
    per_100 = poisson(16, 200, 100.0)
    assert estimate(per_100) == "8"
    assert with_interval(poisson(0, 200, 100.0)) == "0.0 (95 %: 0.0 to 1.8)"


def test_measured_totals_to_three_digits_and_counts_whole() -> None:
    assert measure(70.3449) == "70.3" and measure(0.3333) == "0.333" and measure(1234.5) == "1234"
    assert measure(5) == "5" and measure(0.0) == "0"
    assert places(measured(40.6)) == 1


def test_intervals_of_the_other_figures() -> None:
    mtbf = between(40.0, 15)
    assert mtbf["value"] == pytest.approx(40 / 15)
    assert mtbf["low"] < mtbf["value"] < mtbf["high"]
    assert between(40.0, 0)["value"] is None
    m = median([float(x) for x in range(1, 21)])
    assert m["low"] < m["value"] == 10.5 < m["high"]
    assert median([1.0, 2.0, 3.0])["low"] is None  # too few for an order-statistics interval
    km = mean([7.0, 7.5, 8.0])
    assert km["low"] < 7.5 < km["high"] and mean([7.0])["low"] is None
    autonomy = share(0.69, 70)
    assert autonomy["low"] < 69.0 < autonomy["high"]


def test_the_difference_of_two_rates_is_newcombes_in_points() -> None:
    a, b = wilson(30, 100), wilson(45, 100)
    newcombe = difference(a, b)
    moved = change(proportion(a), proportion(b))
    assert moved["difference"] == pytest.approx(100 * newcombe["difference"])
    assert moved["low"] == pytest.approx(100 * newcombe["low"])
    assert moved["high"] == pytest.approx(100 * newcombe["high"])
    assert moved["significant"] == newcombe["significant"]
    # a measured total: the difference, and no interval
    total = change(measured(40.6), measured(70.2))
    assert total["difference"] == pytest.approx(29.6) and total["low"] is None
