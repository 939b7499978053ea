"""Two seasons (or two tree versions) side by side: every headline figure of the page
(:mod:`~frog_bt.offline.report.headline`: its summary and field reliability), under
the page's labels, in both, and the difference B - A with its 95 % interval (MOVER,
from the two figures' intervals: Newcombe's hybrid score for two rates). A count or
total measured whole has its difference and no interval."""

from __future__ import annotations

from typing import Any

from frog_bt.offline.report import headline
from frog_bt.offline.report.intervals import Change, Rate, change, difference, measured


def figures(t: dict[str, Any]) -> list[headline.Figure]:
    """A season's headline figures, as its page shows them (summary, then reliability)."""
    out = headline.summary(t)
    if t.get("reliability"):
        out += headline.reliability(t["reliability"], t["tours"])
    return out


def compare(a: dict[str, Any], b: dict[str, Any], a_name: str, b_name: str) -> dict[str, Any]:
    """``a`` and ``b``: the totals of the two seasons (:func:`~.totals.totals`, with
    their ``reliability``)."""
    rates_a: dict[str, Rate] = a["rates"]
    rates_b: dict[str, Rate] = b["rates"]
    fa = {f.label: f for f in figures(a)}
    fb = {f.label: f for f in figures(b)}
    rows: list[dict[str, Any]] = []
    for label in [*fa, *(k for k in fb if k not in fa)]:
        one, two = fa.get(label), fb.get(label)
        ref = one or two
        assert ref is not None
        moved: Change = change(
            one.estimate if one else measured(None), two.estimate if two else measured(None)
        )
        rows.append(
            {
                "label": label,
                "unit": ref.unit,
                "how": ref.estimate["how"],
                "shown": [one.shown if one else None, two.shown if two else None],
                **moved,
            }
        )
    return {
        "a": a_name,
        "b": b_name,
        "figures": rows,
        # the rates alone, as fractions (the JSON's earlier shape)
        "rates": {
            name: difference(rates_a[name], rates_b[name]) for name in rates_a if name in rates_b
        },
        "tours": [a["tours"], b["tours"]],
        "completed": [a["completed"], b["completed"]],
        "skipped_b": b["provenance"]["skipped"],
    }
