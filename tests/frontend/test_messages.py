"""Front-end message decoding (CONTRACT §2): every command and event type."""

from __future__ import annotations

from typing import Any

import pytest

from frog_bt.errors import DecodeError
from frog_bt.model.frontend import (
    COMMANDS,
    EVENTS,
    AskTour,
    ContentDone,
    Engagement,
    FinishIntroduction,
    FinishPoi,
    FollowMe,
    FrontendIdle,
    FrontendMessage,
    Projector,
    SpecialContent,
    StartIntroduction,
    StartPoi,
    Tour,
    UserNegative,
    UserPositive,
    Volume,
    decode_message,
    message_fields,
)

# One valid instance of every message type, with its wire fields.
VALID: list[tuple[FrontendMessage, dict[str, Any]]] = [
    (StartIntroduction(icl=True), {"icl": True}),
    (AskTour(engaged=False), {"engaged": False}),
    (AskTour(engaged=None), {"engaged": None}),
    (
        StartPoi(poi="POI1", waypoint="POI1b", part="a"),
        {"poi": "POI1", "waypoint": "POI1b", "part": "a"},
    ),
    (FinishPoi(poi="POI2"), {"poi": "POI2"}),
    (Engagement(level=-0.5), {"level": -0.5}),
    (Engagement(level=None), {"level": None}),
    (FollowMe(on=True), {"on": True}),
    (Volume(percent=80), {"percent": 80}),
    (SpecialContent(spot="toilets"), {"spot": "toilets"}),
    (Projector(on=False), {"on": False}),
    (Tour(state="aborted", reason="battery low"), {"state": "aborted", "reason": "battery low"}),
    (FrontendIdle(), {}),
    (FinishIntroduction(), {}),
    (UserPositive(), {}),
    (UserNegative(), {}),
    (ContentDone(poi="POI3", part="b"), {"poi": "POI3", "part": "b"}),
]


def table_of(cls: type[FrontendMessage]) -> dict[str, type[FrontendMessage]]:
    return COMMANDS if cls.type in COMMANDS else EVENTS


def wire(message: FrontendMessage, fields: dict[str, Any], seq: int = 1) -> dict[str, Any]:
    return {"type": message.type, "seq": seq, **fields}


def test_tables_cover_the_contract() -> None:
    assert set(COMMANDS) == {
        "start_introduction",
        "ask_tour",
        "start_poi",
        "finish_poi",
        "engagement",
        "follow_me",
        "volume",
        "special_content",
        "projector",
        "tour",
    }
    assert set(EVENTS) == {
        "frontend_idle",
        "finish_introduction",
        "user_positive",
        "user_negative",
        "content_done",
    }
    assert {type(m).type for m, _ in VALID} == set(COMMANDS) | set(EVENTS)


@pytest.mark.parametrize(("message", "fields"), VALID, ids=lambda v: getattr(v, "type", ""))
def test_decode_valid(message: FrontendMessage, fields: dict[str, Any]) -> None:
    decoded = decode_message(wire(message, fields), table_of(type(message)))
    assert decoded == message
    assert type(decoded) is type(message)


@pytest.mark.parametrize(("message", "fields"), VALID, ids=lambda v: getattr(v, "type", ""))
def test_message_fields_round_trip(message: FrontendMessage, fields: dict[str, Any]) -> None:
    assert message_fields(message) == fields
    assert "type" not in message_fields(message) and "seq" not in message_fields(message)
    obj = {"type": message.type, "seq": 7, **message_fields(message)}
    assert decode_message(obj, table_of(type(message))) == message


def test_extra_fields_are_ignored() -> None:
    obj = {"type": "follow_me", "seq": 3, "on": True, "note": "ignored"}
    assert decode_message(obj, COMMANDS) == FollowMe(on=True)


@pytest.mark.parametrize(
    ("cls", "name"),
    [
        (cls, name)
        for cls in [*COMMANDS.values(), *EVENTS.values()]
        for name in cls.__struct_fields__
    ],
    ids=lambda v: getattr(v, "type", v),
)
def test_missing_field(cls: type[FrontendMessage], name: str) -> None:
    message, fields = next((m, f) for m, f in VALID if type(m) is cls)
    obj = wire(message, fields)
    del obj[name]
    with pytest.raises(DecodeError, match="missing field") as info:
        decode_message(obj, table_of(cls))
    assert info.value.path == (name,)


# (type, field, bad value): each value has the wrong type or is out of range.
WRONG: list[tuple[str, str, Any]] = [
    ("start_introduction", "icl", 1),
    ("start_introduction", "icl", "true"),
    ("start_introduction", "icl", None),
    ("ask_tour", "engaged", 0),
    ("ask_tour", "engaged", "yes"),
    ("start_poi", "poi", 1),
    ("start_poi", "waypoint", None),
    ("start_poi", "part", "c"),
    ("start_poi", "part", "A"),
    ("finish_poi", "poi", ["POI1"]),
    ("engagement", "level", True),
    ("engagement", "level", "0.5"),
    ("engagement", "level", 1.0001),
    ("engagement", "level", -1.5),
    ("engagement", "level", 2),
    ("engagement", "level", 10**400),
    ("engagement", "level", float("nan")),
    ("engagement", "level", float("inf")),
    ("follow_me", "on", "on"),
    ("volume", "percent", 101),
    ("volume", "percent", -1),
    ("volume", "percent", 50.0),
    ("volume", "percent", True),
    ("volume", "percent", "80"),
    ("special_content", "spot", 3),
    ("projector", "on", None),
    ("tour", "state", "paused"),
    ("tour", "state", None),
    ("tour", "reason", 0),
    ("content_done", "poi", None),
    ("content_done", "part", "ab"),
]


@pytest.mark.parametrize(("type_", "name", "value"), WRONG)
def test_wrong_type_or_range(type_: str, name: str, value: Any) -> None:
    message, fields = next((m, f) for m, f in VALID if m.type == type_)
    obj = {**wire(message, fields), name: value}
    with pytest.raises(DecodeError, match=r"expected|out of range|invalid enum value") as info:
        decode_message(obj, table_of(type(message)))
    assert info.value.path == (name,)


@pytest.mark.parametrize("level", [-1, 1, 0, -1.0, 1.0, 0.0])
def test_level_bounds_are_inclusive(level: float) -> None:
    decoded = decode_message({"type": "engagement", "seq": 1, "level": level}, COMMANDS)
    assert decoded == Engagement(level=float(level))
    assert isinstance(decoded.level, float)  # type: ignore[attr-defined]


@pytest.mark.parametrize("percent", [0, 100])
def test_percent_bounds_are_inclusive(percent: int) -> None:
    obj = {"type": "volume", "seq": 1, "percent": percent}
    assert decode_message(obj, COMMANDS) == Volume(percent=percent)


@pytest.mark.parametrize(
    ("obj", "table"),
    [
        ({"type": "dance", "seq": 1}, EVENTS),
        ({"type": "dance", "seq": 1}, COMMANDS),
        ({"type": "volume", "seq": 1, "percent": 50}, EVENTS),  # a command is no event
        ({"type": "user_positive", "seq": 1}, COMMANDS),  # and an event no command
        ({"type": "ack", "seq": 1}, EVENTS),
        ({"type": None, "seq": 1}, EVENTS),
        ({"type": ["frontend_idle"], "seq": 1}, EVENTS),
        ({"seq": 1}, EVENTS),
    ],
)
def test_unknown_type(obj: dict[str, Any], table: dict[str, type[FrontendMessage]]) -> None:
    with pytest.raises(DecodeError, match="unknown message type") as info:
        decode_message(obj, table)
    assert info.value.path == ("type",)


def test_messages_are_frozen_values() -> None:
    with pytest.raises(AttributeError):
        FollowMe(on=True).on = False  # type: ignore[misc]
    assert FrontendIdle() != FinishIntroduction()
    assert StartPoi("POI1", "POI1a", "a") == StartPoi("POI1", "POI1a", "a")
