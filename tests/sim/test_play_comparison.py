"""`frog_bt.sim.comparison`: the commands a live executive sends held against a recording's,
counted per stream and told in replay's domain terms. Sans-I/O: commands in, counts out."""

from __future__ import annotations

from typing import Any

import pytest

from frog_bt.config import Site, load_site
from frog_bt.model.channels import FRONTEND_OUT
from frog_bt.recordings.commands import Command
from frog_bt.sim.comparison import Comparison

START = 1_780_302_600.0


@pytest.fixture(scope="module")
def site() -> Site:
    return load_site()


def goal(site: Site, waypoint: str, t: float) -> Command:
    """The ``/GotoWayPoint`` the executive sends for ``waypoint`` of the site's table."""
    poi = site.pois[waypoint]
    return Command(
        START + t,
        site.topic("goto"),
        {
            "header": {"frame_id": "map"},
            "pose": {
                "position": {"x": poi.x, "y": poi.y, "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": poi.z, "w": poi.w},
            },
        },
    )


def dock(site: Site, what: str, t: float) -> Command:
    return Command(START + t, site.topic("dock"), {"data": what})


def front(t: float, type_: str, **fields: Any) -> Command:
    return Command(START + t, FRONTEND_OUT, {"type": type_, **fields})


def recorded(site: Site) -> list[Command]:
    return [
        dock(site, "undock", 1.0),
        front(2.0, "tour", state="started", reason=""),
        goal(site, "POI1a", 3.0),
        front(3.0, "follow_me", on=True),
        front(4.0, "engagement", level=0.5),
        front(40.0, "start_poi", poi="POI1", waypoint="POI1a", part="a"),
        goal(site, "POI2a", 60.0),
        dock(site, "dock", 90.0),
    ]


def test_the_same_commands_in_another_interleaving_of_streams_do_not_differ(site: Site) -> None:
    commands = recorded(site)
    comparison = Comparison(site, commands, start=START)
    ros = [c for c in commands if c.channel != FRONTEND_OUT]
    frontend = [c for c in commands if c.channel == FRONTEND_OUT]
    for command in frontend + ros:  # every datagram first: streams are held apart
        assert comparison.got(command) is None
    assert (comparison.received, comparison.differ, comparison.missing) == (7, 0, 0)
    assert comparison.line() == (
        "commands: 7 received, 0 differ from the recording; "
        "engagement meter: 1 readings, 0 off by more than 0.1 "
        "(its windows move with tick timing)"
    )


def test_a_goal_elsewhere_is_counted_and_the_first_told_as_its_waypoint(site: Site) -> None:
    comparison = Comparison(site, recorded(site), start=START)
    assert comparison.got(dock(site, "undock", 1.2)) is None
    assert comparison.got(goal(site, "POI2b", 3.4)) == "waypoint POI1a → POI2b"
    assert comparison.got(goal(site, "POI2a", 61.0)) is None  # back in step
    assert comparison.got(dock(site, "undock", 95.0)) == "data dock → undock"
    assert (comparison.received, comparison.differ) == (4, 2)
    assert comparison.first == "at +3.4 s: waypoint POI1a → POI2b"  # the first one kept
    assert comparison.line().startswith(
        "commands: 4 received, 2 differ from the recording, 3 recorded not received; "
        "first difference at +3.4 s: waypoint POI1a → POI2b"
    )


def test_a_front_end_command_of_another_kind_or_field_is_told_by_both(site: Site) -> None:
    comparison = Comparison(site, recorded(site), start=START)
    assert comparison.got(front(2.0, "tour", state="started", reason="")) is None
    assert (
        comparison.got(front(3.0, "start_poi", poi="POI1", waypoint="POI1a", part="a"))
        == "follow_me on true → start_poi poi POI1 waypoint POI1a part a"
    )
    assert (
        comparison.got(front(41.0, "start_poi", poi="POI1", waypoint="POI1b", part="a"))
        == "waypoint POI1a → POI1b"
    )
    assert comparison.differ == 2
    assert comparison.first.startswith("at +3.0 s: follow_me on true → start_poi")


def test_the_meter_is_counted_apart_within_its_tolerance(site: Site) -> None:
    comparison = Comparison(site, recorded(site), start=START)
    assert comparison.got(front(4.3, "engagement", level=0.45)) is None  # within 0.1
    assert comparison.got(front(6.3, "engagement", level=-0.5)) is None  # one too many
    assert (comparison.meter, comparison.meter_differ) == (2, 1)
    assert (comparison.received, comparison.differ, comparison.first) == (0, 0, "")
    assert "engagement meter: 2 readings, 1 off by more than 0.1" in comparison.line()


def test_commands_past_the_recorded_ones_are_counted_apart_not_as_differences(site: Site) -> None:
    comparison = Comparison(site, [dock(site, "undock", 1.0)], start=START)
    assert comparison.got(dock(site, "undock", 1.0)) is None
    assert comparison.got(dock(site, "dock", 9.0)) is None
    assert (comparison.received, comparison.differ, comparison.beyond) == (2, 0, 1)
    assert comparison.line() == (
        "commands: 2 received, 0 differ from the recording, 1 past the recorded ones"
    )


def test_each_pass_is_held_against_the_recording_afresh(site: Site) -> None:
    commands = recorded(site)
    comparison = Comparison(site, commands, start=START)
    assert comparison.got(dock(site, "undock", 1.0)) is None
    comparison.next_pass(200.0)  # --loop: the 6 others of the first pass never came
    assert (comparison.missed, comparison.missing) == (6, 7)
    assert comparison.got(dock(site, "undock", 201.0)) is None  # the pass starts over
    assert comparison.got(front(202.0, "tour", state="ended", reason="")) == "state started → ended"
    assert comparison.first == "at +202.0 s: state started → ended"
    assert "11 recorded not received" in comparison.line()  # 6 + 5


def test_two_commands_recorded_a_moment_apart_may_come_swapped() -> None:
    from frog_bt.config import load_site
    from frog_bt.model.channels import FRONTEND_OUT
    from frog_bt.recordings.commands import Command
    from frog_bt.sim.comparison import Comparison

    volume = Command(10.0, FRONTEND_OUT, {"type": "volume", "percent": 80})
    follow = Command(10.4, FRONTEND_OUT, {"type": "follow_me", "on": False})
    later = Command(30.0, FRONTEND_OUT, {"type": "finish_poi", "poi": "POI1"})
    c = Comparison(load_site(), [volume, follow, later])
    assert c.got(follow) is None and c.got(volume) is None  # swapped: no difference
    assert c.got(later) is None and c.differ == 0 and c.missing == 0
    far = Comparison(load_site(), [volume, later])
    assert far.got(later) is not None  # 20 s apart: a difference
