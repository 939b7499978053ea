"""The page's headline figures, each once: the rows of its summary and field reliability
tables, with their labels, how the page shows them (to their precision:
:mod:`~frog_bt.offline.report.precision`) and their estimates with 95 % intervals.
The page's two tables are drawn from :func:`summary` and :func:`reliability`, and
``--compare`` sets every figure of both beside the other season's under the same
label (:mod:`~frog_bt.offline.report.compare`), so the two cannot drift apart.

A count or a total the recordings measure whole (tours, visitors, hours in service,
km driven) is ``measured``: no sampling interval. Every other figure is an estimate:
a rate with its Wilson interval, events per tour or per hour with the exact Poisson
interval, a median with its order-statistics interval, a mean over robot-days with
Student's t, autonomy with Wilson's over its clock hours.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from frog_bt.offline.report.intervals import (
    Estimate,
    Rate,
    between,
    measured,
    poisson,
    proportion,
    share,
    wilson,
)
from frog_bt.offline.report.precision import (
    DASH,
    estimate,
    interval,
    measure,
    number,
    places,
    with_interval,
)


@dataclass(frozen=True, slots=True)
class Figure:
    label: str  # as the page's table heads it
    shown: str  # as the page shows it
    estimate: Estimate
    unit: str  # of the estimate and of a difference: " %" (points), " h", " min", ...


def _n(count: int, thing: str) -> str:
    """``1 alert``, ``2 alerts``."""
    return f"{count} {thing}" if count == 1 else f"{count} {thing}s"


def rate(r: Rate) -> str:
    """``76 % (152 of 200; 70 % to 81 %)``, to its precision."""
    e = proportion(r)
    if e["value"] is None:
        return DASH
    return f"{estimate(e, ' %')} ({r['k']} of {r['n']}; {interval(e, ' %')})"


def _rate_figure(label: str, r: Rate) -> Figure:
    return Figure(label, rate(r), proportion(r), " %")


def summary(t: dict[str, Any]) -> list[Figure]:
    """The summary table's rows."""
    r = t["rates"]
    spread = t["tour_minutes"] or {}
    length = t.get("tour_minutes_median") or measured(spread.get("median"))
    p = min(1, places(length))  # the spread is kept to a tenth of a minute
    tours = t["tours"]
    variants = sorted(t["variants"].items())
    return [
        Figure(
            "Tours",
            f"{tours} ({t['completed']} completed, {t['resumed']} resumed)",
            measured(tours),
            "",
        ),
        _rate_figure("Completion rate", r["completion"]),
        _rate_figure("Approach success", r["approach_success"]),
        _rate_figure("Invitation acceptance", r["invitation_acceptance"]),
        Figure(
            "Invitations declined",
            str(t["invitations_declined"]),
            measured(t["invitations_declined"]),
            "",
        ),
        Figure(
            "Visitors reached",
            f"{t['visitors']} ({t['visitors_lost']} lost on the way)",
            measured(t["visitors"]),
            "",
        ),
        *(_rate_figure(f"Part b at {poi}", g) for poi, g in t["engagement"]["by_stop"].items()),
        Figure(
            "Tour length",
            f"median {number(length['value'], p)} min "
            f"(from {number(spread.get('min'), p)} to {number(spread.get('max'), p)} min)",
            length,
            " min",
        ),
        Figure(
            "Distance driven",
            f"{measure(t['distance_m'] / 1000)} km",
            measured(t["distance_m"] / 1000),
            " km",
        ),
        *(
            Figure(
                f"Time-of-day variants: {name}",
                f"{n} of {_n(tours, 'tour')}",
                proportion(wilson(n, tours)),
                " %",
            )
            for name, n in variants
        ),
    ]


def reliability(rel: dict[str, Any], tours: int) -> list[Figure]:
    """The field reliability table's rows (``tours``: the season's, or the day's)."""
    hours = rel["hours_in_service"]
    in_tours = rel.get("hours_in_tours")
    iv = rel["interventions"]
    failures = rel["failures_needing_a_person"]
    ack = rel["time_to_acknowledge_s"]
    ack_e: Estimate = rel.get("time_to_acknowledge") or measured(None)
    km: Estimate = rel.get("km_per_robot_day_estimate") or measured(rel["km_per_robot_day"])
    per_hour = poisson(tours, hours)
    per_100 = poisson(sum(iv.values()), tours, 100.0)
    mtbf = between(hours, failures)
    autonomy = share(rel["autonomy"], rel.get("service_clock_hours", 0))
    split = (
        ""
        if in_tours is None
        else f": {measure(in_tours)} h in tours, {measure(max(0.0, hours - in_tours))} h idle"
    )
    return [
        Figure(
            "Hours in service",
            f"{measure(hours)} h over {_n(rel['robot_days'], 'robot-day')}{split}",
            measured(hours),
            " h",
        ),
        Figure("Tours per hour in service", with_interval(per_hour), per_hour, ""),
        Figure(
            "Interventions per 100 tours",
            with_interval(per_100) + f"; {', '.join(f'{k} {n}' for k, n in iv.items())}",
            per_100,
            "",
        ),
        Figure("Failures that needed a person", str(failures), measured(failures), ""),
        Figure(
            "Mean operating time between them",
            "none in the season" if mtbf["value"] is None else with_interval(mtbf, " h"),
            mtbf,
            " h",
        ),
        Figure(
            "Autonomy (hours with no one needed)",
            with_interval(autonomy, " %"),
            autonomy,
            " %",
        ),
        Figure(
            "Time to acknowledge an alert",
            "none acknowledged"
            if ack is None
            else f"median {with_interval(ack_e, ' s')}, 90th percentile "
            f"{number(ack['p90'], places(ack_e))} s ({_n(rel['acknowledged'], 'alert')})",
            ack_e,
            " s",
        ),
        Figure("Distance per robot-day", with_interval(km, " km"), km, " km"),
    ]


IN_SERVICE = (
    "In service: the time the recordings cover, a robot's tours and the idle time "
    "between them (the idle files of run --record DIR), less the time out of service "
    "(service_off to service_on); recordings of tours alone count the tours' time only."
)
