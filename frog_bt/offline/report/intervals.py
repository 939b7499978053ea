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
    pa, la, ua = a["rate"], a["low"] or 0.0, a["high"] or 0.0
    pb, lb, ub = b["rate"], b["low"] or 0.0, b["high"] or 0.0
    d = pb - pa
    low = d - math.sqrt((pb - lb) ** 2 + (ua - pa) ** 2)
    high = d + math.sqrt((ub - pb) ** 2 + (pa - la) ** 2)
    return {
        "a": a,
        "b": b,
        "difference": d,
        "low": low,
        "high": high,
        "significant": low > 0 or high < 0,
    }
