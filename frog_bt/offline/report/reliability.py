"""Field reliability: how much the robot needed people, per season and per local day,
from the recordings alone (each figure defined in docs/REPORT.md).

* **in service**: the time the recordings cover (a robot's files, overlaps once: its
  tours and, with ``run --record DIR``, its idle files between them), less the time
  out of service (an accepted ``service_off`` to the next ``service_on``); **in
  tours**: the rows' durations, the rest of it idle;
* **interventions**: accepted operator commands by which a person acted, told apart
  (:class:`~frog_bt.offline.report.rows.Intervention`);
* **failures that needed a person**: alerts of severity ERROR (a help request, a fault,
  the robot's link down), each episode once;
* **autonomy**: the share of the time in service spent in clock hours in which nothing
  needed a person (no intervention, no ERROR alert open);
* **time to acknowledge**: an alert's raise to its acknowledgement;
* **km per robot-day**: ``/FROG_pose`` driven, over the days a robot was in service.
"""

from __future__ import annotations

import statistics
from collections import Counter
from datetime import date, datetime
from typing import Any

import numpy as np

from frog_bt.clock import SITE_TZ
from frog_bt.engine.operator import Command
from frog_bt.offline.report.alerts import Episode, episodes, runs_of
from frog_bt.offline.report.facts import HOUR, FileFacts
from frog_bt.offline.report.intervals import mean, median
from frog_bt.offline.report.rows import Intervention, Row, by_robot, intervention

Span = tuple[float, float]


def _merge(spans: list[Span]) -> list[Span]:
    out: list[Span] = []
    for a, b in sorted(spans):
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def _less(spans: list[Span], holes: list[Span]) -> list[Span]:
    out: list[Span] = []
    for a, b in spans:
        cur = a
        for ha, hb in holes:
            if hb <= cur or ha >= b:
                continue
            if ha > cur:
                out.append((cur, ha))
            cur = max(cur, hb)
        if cur < b:
            out.append((cur, b))
    return out


def in_service(files: list[FileFacts]) -> list[Span]:
    """One robot's time in service: its files' spans, less the time out of service."""
    spans = _merge([(f.start, max(f.start, f.end)) for f in files])
    end = spans[-1][1] if spans else 0.0
    holes: list[Span] = []
    off: float | None = None
    for c in sorted((c for f in files for c in f.operator if c.ok), key=lambda c: c.t):
        if c.command == Command.SERVICE_OFF and off is None:
            off = c.t
        elif c.command == Command.SERVICE_ON and off is not None:
            holes.append((off, c.t))
            off = None
    if off is not None:
        holes.append((off, end))
    return _less(spans, holes)


def _hours(spans: list[Span]) -> dict[int, float]:
    """Seconds of ``spans`` in each clock hour (Madrid's offsets are whole hours)."""
    out: dict[int, float] = {}
    for a, b in spans:
        t = a
        while t < b:
            hour = int(t // HOUR)
            step = min(b, (hour + 1) * HOUR) - t
            out[hour] = out.get(hour, 0.0) + step
            t += step
    return out


def _day(t: float) -> date:
    return datetime.fromtimestamp(t, SITE_TZ).date()


def _needed(e: Episode) -> Span:
    """When the alert needed a person: to its clearing (or its acknowledgement)."""
    end = e.cleared if e.cleared is not None else e.acknowledged
    return (e.raised, e.raised if end is None else end)


def _figures(
    tours: int,
    tour_seconds: float,
    service: dict[tuple[str, int], float],
    needed_hours: set[tuple[str, int]],
    kinds: Counter[str],
    failures: int,
    acks: list[float],
    metres: float,
    km_by_robot_day: list[float],
) -> dict[str, Any]:
    seconds = sum(service.values())
    hours = seconds / HOUR
    free = sum(s for h, s in service.items() if h not in needed_hours)
    count = sum(kinds.values())
    robot_days = len(km_by_robot_day)
    return {
        "hours_in_service": round(hours, 2),
        # of which in tours (the rows' durations), and idle between them (the rest)
        "hours_in_tours": round(min(hours, tour_seconds / HOUR), 2),
        "service_clock_hours": sum(s > 0 for s in service.values()),
        "tours_per_hour_in_service": None if hours == 0 else round(tours / hours, 3),
        "interventions": {k.value: kinds.get(k.value, 0) for k in Intervention},
        "interventions_per_100_tours": None if tours == 0 else round(100 * count / tours, 1),
        "failures_needing_a_person": failures,
        "mean_hours_between_failures": None if failures == 0 else round(hours / failures, 2),
        "autonomy": None if seconds == 0 else round(free / seconds, 4),
        "acknowledged": len(acks),
        "time_to_acknowledge_s": None
        if not acks
        else {
            "median": round(statistics.median(acks), 1),
            "p90": round(float(np.percentile(acks, 90)), 1),
        },
        "time_to_acknowledge": median(acks),  # the median's estimate, with its interval
        "robot_days": robot_days,
        "km_per_robot_day": None if robot_days == 0 else round(metres / 1000 / robot_days, 3),
        "km_per_robot_day_estimate": mean(km_by_robot_day),  # over the robot-days
    }


def reliability(files: list[FileFacts], rows: list[Row]) -> dict[str, Any]:
    """The season's figures, and the same per local day (``per_day``)."""
    service: dict[tuple[str, int], float] = {}
    needed: set[tuple[str, int]] = set()
    kinds: list[tuple[float, str]] = []  # (t, intervention)
    failures: list[float] = []
    acks: list[tuple[float, float]] = []  # (raised, seconds to acknowledge)
    metres: dict[tuple[str, int], float] = {}
    for robot, group in by_robot(files).items():
        for h, s in _hours(in_service(group)).items():
            service[robot, h] = s
        calls = [c for f in group for c in f.operator]
        for c in calls:
            what = intervention(c)
            if what is not None:
                kinds.append((c.t, what.value))
                needed.add((robot, int(c.t // HOUR)))
        for e in episodes([a for f in group for a in f.alerts], calls, runs_of(group)):
            if e.to_acknowledge is not None:
                acks.append((e.raised, e.to_acknowledge))
            if e.severity == "ERROR":
                failures.append(e.raised)
                a, b = _needed(e)
                needed.update((robot, h) for h in range(int(a // HOUR), int(b // HOUR) + 1))
        for f in group:
            for h, m in f.metres.items():
                metres[robot, h] = metres.get((robot, h), 0.0) + m
    day_of_hour = {h: _day(h * HOUR) for _, h in {*service, *metres}}
    robot_days = {(r, day_of_hour[h]) for (r, h), s in service.items() if s > 0}
    km: dict[tuple[str, date], float] = dict.fromkeys(robot_days, 0.0)
    for (robot, h), m in metres.items():
        if (robot, day_of_hour[h]) in km:
            km[robot, day_of_hour[h]] += m / 1000

    def figures(day: date | None) -> dict[str, Any]:
        def on(t: float) -> bool:
            return day is None or _day(t) == day

        def hour_on(h: int) -> bool:
            return day is None or day_of_hour[h] == day

        return _figures(
            sum(day is None or r.day == day for r in rows),
            sum(r.duration_s for r in rows if day is None or r.day == day),
            {key: s for key, s in service.items() if hour_on(key[1])},
            needed,
            Counter(k for t, k in kinds if on(t)),
            sum(on(t) for t in failures),
            [s for t, s in acks if on(t)],
            sum(m for (_, h), m in metres.items() if hour_on(h)),
            [k for (_, d), k in sorted(km.items()) if day is None or d == day],
        )

    days = sorted({d for _, d in robot_days} | {r.day for r in rows})
    return {**figures(None), "per_day": {d.isoformat(): figures(d) for d in days}}
