"""Figures shown to their precision: an estimate to the place of the first significant
digit of its standard error (a quarter of its 95 % interval's width: 76 % of 200
tours, not 76.0 %, whose interval is 70 % to 81 %; 2.9 tours an hour, not 2.857), a
measured total to three significant digits (70.3 h, 7.3 km)."""

from __future__ import annotations

import math

from frog_bt.offline.report.intervals import Estimate

DASH = "\u2013"
MOST = 3  # decimals at most


def places(e: Estimate) -> int:
    """The decimals to show ``e`` (and its interval) to."""
    value, low, high = e["value"], e["low"], e["high"]
    if low is not None and high is not None and high > low:
        error = (high - low) / 4
        return min(MOST, max(0, -math.floor(math.log10(error))))
    return significant(value)


def significant(value: float | None, digits: int = 3) -> int:
    """The decimals that show ``value`` to ``digits`` significant digits (none for a
    whole number's extra digits: 1234, not 1.23e3)."""
    if not value or float(value).is_integer():
        return 0
    return min(MOST, max(0, digits - 1 - math.floor(math.log10(abs(value)))))


def number(x: float | None, decimals: int) -> str:
    return DASH if x is None else f"{x:.{decimals}f}"


def measure(x: float | None, digits: int = 3) -> str:
    """A measured total to ``digits`` significant digits at most (the figures kept, to
    a hundredth of an hour, say no more: 0.33 h, not 0.330 h)."""
    text = number(x, significant(x, digits))
    return text.rstrip("0").rstrip(".") if "." in text else text


def estimate(e: Estimate, unit: str = "") -> str:
    """``2.9 tours/h`` (the value alone, to its precision)."""
    return DASH if e["value"] is None else number(e["value"], places(e)) + unit


def with_interval(e: Estimate, unit: str = "") -> str:
    """``2.9 (95 %: 2.5 to 3.3)``; the value alone when it has no interval."""
    if e["value"] is None or e["low"] is None:
        return estimate(e, unit)
    return f"{estimate(e, unit)} (95 %: {interval(e, unit)})"


def signed(x: float, decimals: int, unit: str = "") -> str:
    """``+1.2 h``; a difference that rounds to nothing is ``+0``, never ``-0``."""
    x = round(x, decimals) or 0.0
    return f"{x:+.{decimals}f}{unit}"


def interval(e: Estimate, unit: str = "") -> str:
    """``2.5 to 3.3`` (``unit`` after each), to the value's precision; a dash without one."""
    if e["low"] is None or e["high"] is None:
        return DASH
    p = places(e)
    return f"{number(e['low'], p)}{unit} to {number(e['high'], p)}{unit}"
