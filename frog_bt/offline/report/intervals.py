"""Rates with their 95 % intervals: Wilson's score interval (scipy), and Newcombe's
interval for the difference of two rates, built from the two Wilson intervals.

A rate is ``{"k", "n", "rate", "low", "high"}`` (fractions; ``rate``, ``low`` and
``high`` None when ``n`` is 0), the shape every rate of the report's JSON has.
"""

from __future__ import annotations

import math
from typing import TypedDict

LEVEL = 0.95


class Rate(TypedDict):
    k: int
    n: int
    rate: float | None
    low: float | None
    high: float | None


def wilson(k: int, n: int) -> Rate:
    """``k`` of ``n``, with its 95 % Wilson interval (scipy's ``binomtest``)."""
    if n <= 0:
        return {"k": k, "n": n, "rate": None, "low": None, "high": None}
    from scipy.stats import binomtest  # type: ignore[import-untyped]

    ci = binomtest(k, n).proportion_ci(confidence_level=LEVEL, method="wilson")
    return {"k": k, "n": n, "rate": k / n, "low": float(ci.low), "high": float(ci.high)}


class Difference(TypedDict):
    a: Rate
    b: Rate
    difference: float | None  # b - a
    low: float | None
    high: float | None
    significant: bool  # the interval leaves 0 out


def difference(a: Rate, b: Rate) -> Difference:
    """``b - a`` with Newcombe's 95 % hybrid score interval (method 10, from Wilson's)."""
    if a["rate"] is None or b["rate"] is None:
        return {"a": a, "b": b, "difference": None, "low": None, "high": None, "significant": False}
    pa, pb = a["rate"], b["rate"]
    low, high = _mover(pa, a["low"] or 0.0, a["high"] or 0.0, pb, b["low"] or 0.0, b["high"] or 0.0)
    return {
        "a": a,
        "b": b,
        "difference": pb - pa,
        "low": low,
        "high": high,
        "significant": low > 0 or high < 0,
    }


def _mover(va: float, la: float, ua: float, vb: float, lb: float, ub: float) -> tuple[float, float]:
    """The 95 % interval of ``vb - va`` from each value's own interval (MOVER; with two
    Wilson intervals, Newcombe's hybrid score interval)."""
    d = vb - va
    return (
        d - math.sqrt((vb - lb) ** 2 + (ua - va) ** 2),
        d + math.sqrt((ub - vb) ** 2 + (va - la) ** 2),
    )


# Every other headline figure of the page is an estimate with its 95 % interval in the
# units the page shows it in (a rate in percentage points), so that two seasons'
# figures are set side by side by one rule: the MOVER difference below, of which
# Newcombe's for two rates is the case of two Wilson intervals.


class Estimate(TypedDict):
    value: float | None  # None: nothing to estimate from
    low: float | None  # None with a value: measured, not sampled (no interval)
    high: float | None
    how: str  # the interval's method, in words


Z = 1.959963984540054  # the 95 % normal quantile
TOO_FEW = "too few for an interval"  # an estimate's ``how`` when it has none


def measured(value: float | None) -> Estimate:
    """A total the recordings measure whole (hours, km): no sampling interval."""
    return {"value": value, "low": None, "high": None, "how": "measured"}


def proportion(r: Rate) -> Estimate:
    """A Wilson rate in percentage points."""
    if r["rate"] is None:
        return {"value": None, "low": None, "high": None, "how": "Wilson"}
    return {
        "value": 100 * r["rate"],
        "low": 100 * (r["low"] or 0.0),
        "high": 100 * (r["high"] or 0.0),
        "how": "Wilson",
    }


def share(p: float | None, n: int) -> Estimate:
    """A share ``p`` (a fraction) of ``n`` units that are not each a yes or a no (the
    clock hours of autonomy), in percentage points: Wilson's score interval with ``n``
    as its trials."""
    if p is None or n <= 0:
        return {"value": None, "low": None, "high": None, "how": "Wilson"}
    centre = (p + Z * Z / (2 * n)) / (1 + Z * Z / n)
    half = Z / (1 + Z * Z / n) * math.sqrt(p * (1 - p) / n + Z * Z / (4 * n * n))
    return {
        "value": 100 * p,
        "low": 100 * max(0.0, centre - half),
        "high": 100 * min(1.0, centre + half),
        "how": f"Wilson, {n} clock hours as trials",
    }


def poisson(count: int, exposure: float, per: float = 1.0) -> Estimate:
    """``count`` events over ``exposure`` (tours, hours), per ``per`` of it: the exact
    (Garwood) interval of a Poisson count."""
    if exposure <= 0:
        return {"value": None, "low": None, "high": None, "how": "Poisson (exact)"}
    from scipy.stats import chi2

    low = 0.0 if count == 0 else float(chi2.ppf((1 - LEVEL) / 2, 2 * count)) / 2
    high = float(chi2.ppf(1 - (1 - LEVEL) / 2, 2 * count + 2)) / 2
    scale = per / exposure
    return {
        "value": count * scale,
        "low": low * scale,
        "high": high * scale,
        "how": "Poisson (exact)",
    }


def between(exposure: float, count: int) -> Estimate:
    """``exposure`` per event (hours between failures): the exact Poisson interval of
    ``count``, inverted. None with no event."""
    if count <= 0:
        return {"value": None, "low": None, "high": None, "how": "Poisson (exact)"}
    rate = poisson(count, 1.0)
    return {
        "value": exposure / count,
        "low": exposure / (rate["high"] or math.inf),
        "high": exposure / rate["low"] if rate["low"] else None,
        "how": "Poisson (exact)",
    }


def median(values: list[float]) -> Estimate:
    """The median with its distribution-free interval (order statistics, binomial)."""
    if not values:
        return {"value": None, "low": None, "high": None, "how": "order statistics"}
    import statistics

    from scipy.stats import binom

    xs = sorted(values)
    n = len(xs)
    j = int(binom.ppf((1 - LEVEL) / 2, n, 0.5))
    if j < 1:  # under 6 values even the smallest to the largest hold it less often
        value = float(statistics.median(xs))
        return {"value": value, "low": None, "high": None, "how": TOO_FEW}
    return {
        "value": float(statistics.median(xs)),
        "low": float(xs[j - 1]),
        "high": float(xs[n - j]),
        "how": "order statistics",
    }


def mean(values: list[float]) -> Estimate:
    """The mean with Student's t interval (no interval from one value)."""
    if not values:
        return {"value": None, "low": None, "high": None, "how": "Student's t"}
    import statistics

    m = statistics.fmean(values)
    if len(values) < 2:
        return {"value": m, "low": None, "high": None, "how": TOO_FEW}
    from scipy.stats import t

    half = float(t.ppf(1 - (1 - LEVEL) / 2, len(values) - 1)) * statistics.stdev(values)
    half /= math.sqrt(len(values))
    return {"value": m, "low": m - half, "high": m + half, "how": "Student's t"}


class Change(TypedDict):
    a: Estimate
    b: Estimate
    difference: float | None  # b - a
    low: float | None  # None with a difference: a measured total, no interval
    high: float | None
    significant: bool  # the interval leaves 0 out


def change(a: Estimate, b: Estimate) -> Change:
    """``b - a`` with its 95 % interval by MOVER (the method of variance estimates
    recovery: Newcombe's hybrid score interval when both are Wilson rates)."""
    va, vb = a["value"], b["value"]
    if va is None or vb is None:
        return {"a": a, "b": b, "difference": None, "low": None, "high": None, "significant": False}
    d = vb - va
    la, ua, lb, ub = a["low"], a["high"], b["low"], b["high"]
    if la is None or ua is None or lb is None or ub is None:
        return {"a": a, "b": b, "difference": d, "low": None, "high": None, "significant": False}
    low, high = _mover(va, la, ua, vb, lb, ub)
    return {
        "a": a,
        "b": b,
        "difference": d,
        "low": low,
        "high": high,
        "significant": low > 0 or high < 0,
    }
