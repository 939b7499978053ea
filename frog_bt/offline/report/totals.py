"""The figures over a corpus of tour rows (docs/REPORT.md): counts, rates with their
intervals, distributions, the failure causes, per-day trends, the stop-by-stop funnel
and engagement by stop, hour and variant. Everything is read from the rows' typed
fields: nothing here parses text."""

from __future__ import annotations

import statistics
from collections import Counter
from typing import Any

from frog_bt.offline.report.intervals import Rate, median, wilson
from frog_bt.offline.report.rows import Row, Visit


def _rate(num: int, den: int) -> float | None:
    return None if den == 0 else num / den


def _gate(visits: list[Visit]) -> Rate:
    """Part b played, of the visits where the gate decided."""
    decided = [v for v in visits if v.decision != "none"]
    return wilson(sum(v.decision == "b" for v in decided), len(decided))


def funnel(rows: list[Row], order: list[str]) -> dict[str, int]:
    """Visitors who started a tour, reached each content stop (a skipped stop is not
    reached: :mod:`frog_bt.model.tours`), finished. A stop reached again in a tour is a
    new visitor's (one was lost on the way), so each visit counts."""
    out = {"started": sum(r.visitors for r in rows), **dict.fromkeys(order, 0), "finished": 0}
    for r in rows:
        for poi in r.stops_reached:
            if poi in out and poi not in ("started", "finished"):
                out[poi] += 1
        if r.ended == "ended" and r.visitors:
            out["finished"] += 1
    return out


def totals(
    rows: list[Row], face_stops: list[str], unreadable: int = 0, order: list[str] | None = None
) -> dict[str, Any]:
    """Everything the report's summary shows; rates are fractions (None: nothing to count)."""
    n = len(rows)
    completed = sum(r.ended == "ended" for r in rows)
    approaches = sum(r.approaches for r in rows)
    asked = sum(r.invitations for r in rows)
    visits = [v for r in rows for v in r.engagement]
    gate = {poi: _gate([v for v in visits if v.poi == poi]) for poi in face_stops}
    per_stop: dict[str, list[float]] = {}
    for r in rows:
        for st in r.time_at_stops:
            per_stop.setdefault(st.poi, []).append(st.seconds)
    distance_per_day: dict[str, float] = {}
    for r in rows:
        key = r.day.isoformat()
        distance_per_day[key] = round(distance_per_day.get(key, 0.0) + r.distance_m, 1)
    events: Counter[tuple[str, str]] = Counter()
    tours_with: Counter[tuple[str, str]] = Counter()
    for r in rows:
        mine = Counter((i.cause.value, i.detail) for i in r.incidents)
        events.update(mine)
        tours_with.update(mine.keys())
    hours = Counter(r.hour for r in rows)
    span = range(min(hours), max(hours) + 1) if hours else range(0)
    days = sorted({r.day for r in rows})
    by_hour: dict[int, list[Visit]] = {}
    for r in rows:
        by_hour.setdefault(r.hour, []).extend(r.engagement)
    rates = {
        "completion": wilson(completed, n),
        "approach_success": wilson(sum(r.approaches_accepted for r in rows), approaches),
        "invitation_acceptance": wilson(sum(r.invitations_accepted for r in rows), asked),
        **{f"part_b:{poi}": g for poi, g in gate.items()},
    }
    return {
        "tours": n,
        "unreadable_files": unreadable,
        "completed": completed,
        "completion_rate": _rate(completed, n),
        "resumed": sum(r.resumed for r in rows),
        "tours_per_day": {d.isoformat(): sum(r.day == d for r in rows) for d in days},
        "tours_per_hour": {str(h): hours.get(h, 0) for h in span},
        "visitors": sum(r.visitors for r in rows),
        "visitors_lost": sum(r.visitors_lost for r in rows),
        "approaches": approaches,
        "approach_success": _rate(sum(r.approaches_accepted for r in rows), approaches),
        "invitations": asked,
        "invitation_acceptance": _rate(sum(r.invitations_accepted for r in rows), asked),
        "invitations_declined": sum(r.invitations_declined for r in rows),
        "part_b_rate": {poi: g["rate"] for poi, g in gate.items()},
        "gate_decisions": {poi: g["n"] for poi, g in gate.items()},
        "rates": rates,
        "tour_minutes": _spread([r.duration_s / 60 for r in rows]),
        "tour_minutes_median": median([r.duration_s / 60 for r in rows]),  # with its interval
        "stop_seconds": {poi: _spread(v) for poi, v in per_stop.items()},
        "distance_per_day_m": distance_per_day,
        "distance_m": round(sum(r.distance_m for r in rows), 1),
        "failure_causes": [
            {"cause": c, "detail": d, "events": k, "tours": tours_with[c, d]}
            for (c, d), k in events.most_common()
        ],
        "variants": dict(Counter(v for r in rows for v in r.variants)),
        "per_day": {d.isoformat(): _day([r for r in rows if r.day == d], face_stops) for d in days},
        "funnel": funnel(rows, order or face_stops),
        "engagement": {
            "by_stop": {poi: gate[poi] for poi in face_stops},
            "by_hour": {str(h): _gate(v) for h, v in sorted(by_hour.items())},
            "by_variant": {
                wp: _gate([v for v in visits if v.waypoint == wp])
                for wp in sorted({v.waypoint for v in visits})
            },
        },
    }


def _day(rows: list[Row], face_stops: list[str]) -> dict[str, Any]:
    """One day's trend figures."""
    visits = [v for r in rows for v in r.engagement if v.poi in face_stops]
    return {
        "tours": len(rows),
        "completion": wilson(sum(r.ended == "ended" for r in rows), len(rows)),
        "part_b": _gate(visits),
        "interventions": sum(r.interventions for r in rows),
    }


def _spread(values: list[float]) -> dict[str, float] | None:
    if not values:
        return None
    ordered = sorted(values)
    return {
        "n": len(values),
        "min": round(ordered[0], 1),
        "median": round(statistics.median(ordered), 1),
        "max": round(ordered[-1], 1),
        "mean": round(statistics.fmean(ordered), 1),
    }
