"""Two seasons (or two tree versions) side by side: each rate of the report in both,
and the difference with its 95 % interval (Newcombe's, from the two Wilson intervals)."""

from __future__ import annotations

from typing import Any

from frog_bt.offline.report.intervals import Rate, difference


def compare(a: dict[str, Any], b: dict[str, Any], a_name: str, b_name: str) -> dict[str, Any]:
    """``a`` and ``b``: the totals of the two seasons (:func:`~.totals.totals`)."""
    rates_a: dict[str, Rate] = a["rates"]
    rates_b: dict[str, Rate] = b["rates"]
    return {
        "a": a_name,
        "b": b_name,
        "rates": {
            name: difference(rates_a[name], rates_b[name]) for name in rates_a if name in rates_b
        },
        "tours": [a["tours"], b["tours"]],
        "completed": [a["completed"], b["completed"]],
        "skipped_b": b["provenance"]["skipped"],
    }
