"""Typed front-end datagrams (CONTRACT §2).

Each message type is a frozen dataclass with a class attribute ``type`` (its
wire name). :func:`decode_message` turns a datagram's JSON object into one of
them or raises :class:`~frog_bt.errors.DecodeError`; :func:`message_fields`
gives the JSON fields of a message (without ``type`` and ``seq``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

from frog_bt.errors import DecodeError


@dataclass(frozen=True, slots=True)
class FrontendMessage:
    type: ClassVar[str] = ""
    # field name -> kind: bool, bool?, str, int, level?, part
    spec: ClassVar[dict[str, str]] = {}


# ------------------------------------------------------------------ commands


@dataclass(frozen=True, slots=True)
class StartIntroduction(FrontendMessage):
    icl: bool
    type: ClassVar[str] = "start_introduction"
    spec: ClassVar[dict[str, str]] = {"icl": "bool"}


@dataclass(frozen=True, slots=True)
class AskTour(FrontendMessage):
    engaged: bool | None
    type: ClassVar[str] = "ask_tour"
    spec: ClassVar[dict[str, str]] = {"engaged": "bool?"}


@dataclass(frozen=True, slots=True)
class StartPoi(FrontendMessage):
    poi: str
    waypoint: str
    part: str
    type: ClassVar[str] = "start_poi"
    spec: ClassVar[dict[str, str]] = {"poi": "str", "waypoint": "str", "part": "part"}


@dataclass(frozen=True, slots=True)
class FinishPoi(FrontendMessage):
    poi: str
    type: ClassVar[str] = "finish_poi"
    spec: ClassVar[dict[str, str]] = {"poi": "str"}


@dataclass(frozen=True, slots=True)
class Engagement(FrontendMessage):
    level: float | None
    type: ClassVar[str] = "engagement"
    spec: ClassVar[dict[str, str]] = {"level": "level?"}


@dataclass(frozen=True, slots=True)
class FollowMe(FrontendMessage):
    on: bool
    type: ClassVar[str] = "follow_me"
    spec: ClassVar[dict[str, str]] = {"on": "bool"}


@dataclass(frozen=True, slots=True)
class Volume(FrontendMessage):
    percent: int
    type: ClassVar[str] = "volume"
    spec: ClassVar[dict[str, str]] = {"percent": "percent"}


@dataclass(frozen=True, slots=True)
class SpecialContent(FrontendMessage):
    spot: str
    type: ClassVar[str] = "special_content"
    spec: ClassVar[dict[str, str]] = {"spot": "str"}


@dataclass(frozen=True, slots=True)
class Projector(FrontendMessage):
    on: bool
    type: ClassVar[str] = "projector"
    spec: ClassVar[dict[str, str]] = {"on": "bool"}


@dataclass(frozen=True, slots=True)
class Tour(FrontendMessage):
    state: str
    reason: str
    type: ClassVar[str] = "tour"
    spec: ClassVar[dict[str, str]] = {"state": "tour_state", "reason": "str"}


# ------------------------------------------------------------------ events


@dataclass(frozen=True, slots=True)
class FrontendIdle(FrontendMessage):
    type: ClassVar[str] = "frontend_idle"


@dataclass(frozen=True, slots=True)
class FinishIntroduction(FrontendMessage):
    type: ClassVar[str] = "finish_introduction"


@dataclass(frozen=True, slots=True)
class UserPositive(FrontendMessage):
    type: ClassVar[str] = "user_positive"


@dataclass(frozen=True, slots=True)
class UserNegative(FrontendMessage):
    type: ClassVar[str] = "user_negative"


@dataclass(frozen=True, slots=True)
class ContentDone(FrontendMessage):
    poi: str
    part: str
    type: ClassVar[str] = "content_done"
    spec: ClassVar[dict[str, str]] = {"poi": "str", "part": "part"}


COMMANDS: dict[str, type[FrontendMessage]] = {
    cls.type: cls
    for cls in (StartIntroduction, AskTour, StartPoi, FinishPoi, Engagement, FollowMe, Volume,
                SpecialContent, Projector, Tour)
}
EVENTS: dict[str, type[FrontendMessage]] = {
    cls.type: cls
    for cls in (FrontendIdle, FinishIntroduction, UserPositive, UserNegative, ContentDone)
}
TOUR_STATES = ("started", "ended", "aborted")


def _check(kind: str, value: Any, name: str) -> Any:
    def bad(expected: str) -> DecodeError:
        return DecodeError(f"expected {expected}, got {value!r}"[:200], (name,))

    if kind == "bool":
        if not isinstance(value, bool):
            raise bad("a boolean")
    elif kind == "bool?":
        if value is not None and not isinstance(value, bool):
            raise bad("a boolean or null")
    elif kind == "str":
        if not isinstance(value, str):
            raise bad("a string")
    elif kind == "part":
        if value not in ("a", "b"):
            raise bad('"a" or "b"')
    elif kind == "tour_state":
        if value not in TOUR_STATES:
            raise bad(" or ".join(f'"{s}"' for s in TOUR_STATES))
    elif kind == "percent":
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 100:
            raise bad("an integer 0..100")
    elif kind == "level?":
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise bad("a number in [-1, 1] or null")
        # An int too large for a float (JSON allows 10**400) is out of range, not a crash.
        if isinstance(value, int) and not -1 <= value <= 1:
            raise bad("a number in [-1, 1] or null")
        value = float(value)
        if not (math.isfinite(value) and -1.0 <= value <= 1.0):
            raise bad("a number in [-1, 1] or null")
    else:  # pragma: no cover - a spec typo is a programming error
        raise AssertionError(kind)
    return value


def decode_message(obj: dict[str, Any], table: dict[str, type[FrontendMessage]]) -> FrontendMessage:
    """The typed message for a datagram object whose ``type`` is in ``table``."""
    type_ = obj.get("type")
    cls = table.get(type_) if isinstance(type_, str) else None
    if cls is None:
        raise DecodeError(f"unknown message type {type_!r}"[:200], ("type",))
    kwargs = {}
    for name, kind in cls.spec.items():
        if name not in obj:
            raise DecodeError("missing field", (name,))
        kwargs[name] = _check(kind, obj[name], name)
    return cls(**kwargs)


def message_fields(message: FrontendMessage) -> dict[str, Any]:
    return {f.name: getattr(message, f.name) for f in dataclasses.fields(message)}
