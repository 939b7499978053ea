"""The figures over a corpus of tour rows (docs/REPORT.md): counts, rates, distributions."""

from __future__ import annotations

import json
import statistics
from collections import Counter
from typing import Any

from frog_bt.offline.report.rows import Row


def _rate(num: int, den: int) -> float | None:
    return None if den == 0 else num / den


def totals(rows: list[Row], face_stops: list[str], unreadable: int = 0) -> dict[str, Any]:
    """Everything the report's summary shows; rates are fractions (None: nothing to count)."""
    n = len(rows)
    completed = sum(r.ended == "ended" for r in rows)
    approaches = sum(r.approaches for r in rows)
    asked = sum(r.invitations for r in rows)
    part_b: dict[str, float | None] = {}
    decided: dict[str, int] = {}
    for poi in face_stops:
        gate = [
            v["decision"]
            for r in rows
            for v in json.loads(r.engagement)
            if v["poi"] == poi and v["decision"] != "none"
        ]
        decided[poi] = len(gate)
        part_b[poi] = _rate(gate.count("b"), len(gate))
    per_stop: dict[str, list[float]] = {}
    for r in rows:
        for poi, s in json.loads(r.time_at_stops).items():
            per_stop.setdefault(poi, []).append(s)
    distance_per_day: dict[str, float] = {}
    for r in rows:
        distance_per_day[r.day] = round(distance_per_day.get(r.day, 0.0) + r.distance_m, 1)
    causes: Counter[str] = Counter()
    for r in rows:
        if r.ended == "aborted":
            causes[f"aborted: {r.reason or '?'}"] += 1
        elif r.ended == "cut":
            causes["recording ends mid-tour"] += 1
        for skip in filter(None, r.stops_skipped.split("; ")):
            causes[f"stop skipped: {skip.split(': ', 1)[-1]}"] += 1
        for fault in filter(None, r.faults.split("; ")):
            causes[f"fault: {fault}"] += 1
    durations = [r.duration_s for r in rows]
    return {
        "tours": n,
        "unreadable_files": unreadable,
        "completed": completed,
        "completion_rate": _rate(completed, n),
        "resumed": sum(r.resumed for r in rows),
        "tours_per_day": dict(sorted(Counter(r.day for r in rows).items())),
        "tours_per_hour": dict(sorted(Counter(r.hour for r in rows).items())),
        "visitors": sum(r.visitors for r in rows),
        "approaches": approaches,
        "approach_success": _rate(sum(r.approaches_accepted for r in rows), approaches),
        "invitations": asked,
        "invitation_acceptance": _rate(sum(r.invitations_accepted for r in rows), asked),
        "invitations_declined": sum(r.invitations_declined for r in rows),
        "part_b_rate": part_b,
        "gate_decisions": decided,
        "tour_minutes": _spread([d / 60 for d in durations]),
        "stop_seconds": {poi: _spread(v) for poi, v in per_stop.items()},
        "distance_per_day_m": distance_per_day,
        "distance_m": round(sum(r.distance_m for r in rows), 1),
        "failure_causes": dict(causes.most_common(10)),
        "variants": dict(Counter(v for r in rows for v in filter(None, r.variants.split(";")))),
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
