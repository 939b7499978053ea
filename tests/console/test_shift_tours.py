"""A shift's tours (frog_bt/live/console/shift.py) are the one count's (the TourLedger the
console's day reads), for the shift's span: a ``tour started`` or a ``tour ended`` said
again is not a second tour, a tour started in one shift and ended in the next is
started in the first and completed in the second, and the shifts add up to the day."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.config import load_site
from frog_bt.live.console.day import Day
from frog_bt.live.console.shift import Shift
from frog_bt.model.events import Event, FrontendOut
from frog_bt.model.frontend import Tour
from frog_bt.model.outcomes import TourState

T0 = 1_780_905_600.0  # 2026-06-08 10:00 (+02:00)


def _host() -> Any:
    """What a shift and a day read of their host: the site, its clock's zone, a board."""
    return SimpleNamespace(
        site=load_site(),
        clock=SimpleNamespace(tz=SITE_TZ),
        core=SimpleNamespace(board={}),
        links=None,
    )


def _tour(t: float, state: str, reason: str = "") -> Event:
    return FrontendOut(T0 + t, Tour(TourState(state), reason))


def test_a_shift_counts_the_tours_as_the_day_does() -> None:
    host = _host()
    shift, day = Shift([], list), Day("en")
    shift.attach(host)
    day.attach(host)
    first = [
        _tour(1, "started"),
        _tour(2, "started"),  # said again (taken anew after a resend): the same tour
        _tour(60, "ended"),
        _tour(61, "ended"),  # said again after the tour's end: nothing
        _tour(100, "started"),
    ]
    second = [
        _tour(200, "aborted", "battery 12% below 20%"),
        _tour(300, "started"),
        _tour(400, "ended"),
    ]
    for event in first:
        shift.on_event(event)
        day.on_event(event)
    one = shift.hand_over(T0 + 150, by="console")
    assert one.tours == {"started": 2, "completed": 1, "aborted": 0}
    for event in second:
        shift.on_event(event)
        day.on_event(event)
    two = shift.hand_over(T0 + 500)
    # the tour started in the first shift is aborted in the second
    assert two.tours == {"started": 1, "completed": 1, "aborted": 1}
    days = {"started": day.started, "completed": day.completed, "aborted": day.aborted}
    assert {k: one.tours[k] + two.tours[k] for k in days} == days
    assert shift.tours == dict.fromkeys(days, 0)  # the next shift starts empty
