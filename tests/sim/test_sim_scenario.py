"""Scenario files: built-ins, defaults, extends, and errors naming file, path and expectation."""

from __future__ import annotations

from collections.abc import Callable
from datetime import datetime
from pathlib import Path

import pytest

from frog_bt.clock import SITE_TZ
from frog_bt.errors import ConfigError
from frog_bt.sim import command
from frog_bt.sim.scenario import (
    ContentParts,
    Scenario,
    builtin_scenarios,
    load_scenario,
    parse_scenario,
)
from frog_bt.sim.site import PoiPose
from frog_bt.sim.world import World


def write(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def error_of(tmp_path: Path, text: str) -> ConfigError:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    assert info.value.file == str(path)
    return info.value


def test_every_builtin_loads_and_is_listed_in_help() -> None:
    names = builtin_scenarios()
    assert {"default", "morning", "afternoon"} <= set(names)
    for name in names:
        scenario = load_scenario(name)
        assert scenario.name == name
        assert name in (command.__doc__ or "")


def test_default_scenario() -> None:
    s = load_scenario("default")
    assert s.start_time == datetime.fromisoformat("2026-06-01T10:30:00+02:00")
    assert s.start_epoch == s.start_time.timestamp()
    (visitor,) = s.visitors
    assert (visitor.position.x, visitor.position.y) == pytest.approx((103, 36), abs=1.0)
    assert visitor.detected_orientation == 180.0 and visitor.answer == "positive"
    assert visitor.faces == "engaged" and visitor.follow


def test_variants_only_change_the_start_time() -> None:
    default = load_scenario("default")
    for name, hour in (("morning", 9), ("afternoon", 15)):
        variant = load_scenario(name)
        assert variant.start_time.astimezone(SITE_TZ).hour == hour
        assert variant.visitors == default.visitors and variant.content == default.content


def test_an_empty_file_is_every_default(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, ""))
    assert s.speed == 50 and s.dt == 0.1 and s.visitors == []
    assert s.navigation.speed == 0.6 and s.docking.undock_time == 5
    assert s.docking.dock_time == 10 and s.battery.drain_per_hour == 5
    assert s.introduction_seconds == 20 and s.content_seconds("POI1", "POI1a", "a") == 30
    assert s.frontend.idle_at == 1 and s.frontend.idle_after_tour == 5


def test_extends_merges_mappings_and_replaces_lists(tmp_path: Path) -> None:
    write(
        tmp_path,
        "speed: 10\nnavigation: {speed: 1.0, approach_time: 4}\n"
        "visitors: [{id: 1, position: [0, 0]}]\n",
        "base.yaml",
    )
    s = load_scenario(
        write(tmp_path, "extends: base.yaml\nnavigation: {speed: 2.0}\nvisitors: []\n")
    )
    assert s.speed == 10 and s.navigation.speed == 2.0 and s.navigation.approach_time == 4
    assert s.visitors == [] and s.name == "s"


def test_naive_start_time_is_local_time_at_the_site(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, 'start_time: "2026-06-01 12:00:00"\n'))
    assert s.start_time.astimezone(SITE_TZ).hour == 12
    assert s.start_time.utcoffset() is not None


def test_content_lookup_by_poi_then_waypoint_then_default(
    scenario: Callable[..., Scenario],
) -> None:
    s = scenario(
        content={
            "default": 12,
            "introduction": 7,
            "POI1": {"a": 40, "b": 20},
            "POI2b": 9,
            "POI3": {"a": 5},
        }
    )
    assert s.introduction_seconds == 7
    assert s.content_seconds("POI1", "POI1a", "a") == 40
    assert s.content_seconds("POI1", "POI1b", "b") == 20
    assert s.content_seconds("POI2", "POI2b", "a") == 9
    assert s.content_seconds("POI2", "POI2a", "a") == 12
    assert s.content_seconds("POI3", "POI3", "b") == 12
    assert isinstance(s.content["POI1"], ContentParts)


@pytest.mark.parametrize(
    ("text", "path", "expected"),
    [
        ("colour: red\n", ("colour",), "unknown key"),
        (
            "visitors: [{id: 1, position: [0, 0], hat: true}]\n",
            ("visitors", 0, "hat"),
            "unknown key",
        ),
        ("visitors: [{position: [0, 0]}]\n", ("visitors", 0, "id"), "missing"),
        (
            "visitors: [{id: 1, position: [0, 0], faces: happy}]\n",
            ("visitors", 0, "faces"),
            "expected one of engaged, bored, mixed, far, not_facing, or a list",
        ),
        (
            "visitors: [{id: 1, position: [0, 0], faces: [0.5, 2]}]\n",
            ("visitors", 0, "faces"),
            "a list of numbers in [-1, 1]",
        ),
        (
            "visitors: [{id: 1, position: [1, 2, 3]}]\n",
            ("visitors", 0, "position"),
            "expected [x, y] or {x, y}",
        ),
        (
            "visitors: [{id: 1, position: [0, 0], approach: [maybe]}]\n",
            ("visitors", 0, "approach", 0),
            "'succeeded', 'failed' or 'aborted'",
        ),
        (
            "visitors: [{id: 1, position: [0, 0], orientation: 90, facing: true}]\n",
            ("visitors", 0),
            "not both",
        ),
        (
            "visitors: [{id: 1, position: [0, 0]}, {id: 1, position: [1, 1]}]\n",
            ("visitors", 1, "id"),
            "duplicate visitor id 1",
        ),
        (
            "visitors: [{id: 1, position: [0, 0], wander_off: {}}]\n",
            ("visitors", 0, "wander_off"),
            "exactly one of heading_to",
        ),
        (
            "navigation: {failures: [{goal: 1, poi: POI1}]}\n",
            ("navigation", "failures", 0),
            "exactly one of goal: N or poi: NAME",
        ),
        (
            "navigation: {failures: [{goal: 1, result: lost}]}\n",
            ("navigation", "failures", 0, "result"),
            "'failed' or 'aborted'",
        ),
        ("navigation: {speed: -1}\n", ("navigation", "speed"), "greater than 0"),
        ("speed: fast\n", ("speed",), "got 'fast'"),
        ("faults: [{at: 5, name: x, level: 1}]\n", ("faults", 0, "level"), "2 or 3"),
        ("content: {POI1: {c: 3}}\n", ("content", "POI1", "c"), 'expected "a" or "b"'),
        ("content: {default: {a: 3}}\n", ("content", "default"), "expected seconds > 0"),
        ("content: {POI1: -4}\n", ("content", "POI1"), "seconds > 0 or {a: seconds"),
    ],
)
def test_errors_name_file_path_and_expectation(
    tmp_path: Path, text: str, path: tuple[str | int, ...], expected: str
) -> None:
    error = error_of(tmp_path, text)
    assert error.path == path, str(error)
    assert expected in error.detail, str(error)
    assert error.line is not None  # the node's line and column in the file
    assert str(error).startswith(f"{error.file}:{error.line[0]}:{error.line[1]}: ")


def test_not_yaml(tmp_path: Path) -> None:
    error = error_of(tmp_path, "visitors: [\n")
    assert error.path == () and "not valid YAML" in error.detail


def test_not_a_mapping(tmp_path: Path) -> None:
    error = error_of(tmp_path, "- 1\n- 2\n")
    assert "expected a mapping of scenario keys" in error.detail


def test_unknown_name_lists_the_builtins() -> None:
    with pytest.raises(ConfigError) as info:
        load_scenario("no_such_scenario")
    assert "default" in info.value.detail and "built-in" in info.value.detail


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as info:
        load_scenario(tmp_path / "missing.yaml")
    assert "cannot read" in info.value.detail


def test_world_refuses_unknown_pois(pois: dict[str, PoiPose]) -> None:
    s = parse_scenario(
        {"visitors": [{"id": 1, "position": [0, 0], "wander_off": {"heading_to": "POI9"}}]},
        "x.yaml",
    )
    with pytest.raises(ConfigError) as info:
        World(s, pois)
    assert info.value.path == ("visitors", 0, "wander_off", "heading_to")
    assert "unknown POI 'POI9'" in info.value.detail
    with pytest.raises(ConfigError, match=r"robot\.start"):
        World(parse_scenario({"robot": {"start": "NOWHERE"}}), pois)
    World(parse_scenario({"navigation": {"failures": [{"poi": "POI2"}]}}), pois)  # variants ok


@pytest.mark.parametrize("name", builtin_scenarios())
def test_a_scenario_survives_a_json_round_trip(name: str) -> None:
    s = load_scenario(name)
    s = s.model_copy(update={"content": {**s.content, "POI1": ContentParts(a=40)}})
    assert parse_scenario(s.model_dump(mode="json")) == s
