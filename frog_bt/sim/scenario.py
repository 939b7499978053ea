"""Simulator scenarios: what the simulated robot, visitors and front end do.

A scenario is a YAML file validated up front into :class:`Scenario` (pydantic,
unknown keys refused); an error names the file, the path inside it and what
was expected::

    my.yaml: visitors[0].faces: expected one of engaged, bored, mixed, far,
    not_facing, or a list of numbers in [-1, 1], got 'happy'

Built-in scenarios live in ``frog_bt/sim/scenarios/`` and are loaded by name
(``default``); anything else is a file path. ``extends: NAME|FILE`` starts from
another scenario and overrides it key by key (mappings merge, lists replace).
All ``at`` times are seconds of simulated time after the scenario starts.
"""

from __future__ import annotations

import math
from datetime import datetime
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from frog_bt.clock import SITE_TZ
from frog_bt.errors import ConfigError
from frog_bt.model import frontend as fm
from frog_bt.yamlfile import PathError, load_yaml, validate

Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Finite = Annotated[float, Field(allow_inf_nan=False)]
Int32 = Annotated[int, Field(ge=-(2**31), lt=2**31)]
Count = Annotated[int, Field(ge=0)]

DEFAULT_START = datetime.fromisoformat("2026-06-01T10:30:00+02:00")
FACE_PROFILES = ("engaged", "bored", "mixed", "far", "not_facing")
Outcome = Literal["succeeded", "failed", "aborted"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class XY(_Model):
    """A map-frame position, written ``{x: 1, y: 2}`` or ``[1, 2]``."""

    x: Finite
    y: Finite

    @model_validator(mode="before")
    @classmethod
    def _from_pair(cls, value: Any) -> Any:
        if isinstance(value, list | tuple):
            if len(value) != 2:
                raise ValueError(f"expected [x, y] or {{x, y}}, got a list of {len(value)}")
            return {"x": value[0], "y": value[1]}
        return value


class PoseSpec(_Model):
    """A map-frame pose; ``yaw`` in degrees (0 = +x, counter-clockwise)."""

    x: Finite
    y: Finite
    yaw: Finite = 0.0


class RobotSpec(_Model):
    """Where the robot starts: at POI ``start`` (also the dock), or at ``pose``."""

    start: str = "SHOP"
    pose: PoseSpec | None = None
    docked: bool = True


class NavFailure(_Model):
    """Make a goal end in 3 (failed) or 4 (aborted) after ``after`` seconds of driving.

    Either ``goal: N`` (the Nth ``/GotoWayPoint`` of the run, from 1) or
    ``poi: NAME`` with ``times: K`` (the first K goals to that POI or its variants).
    """

    goal: Annotated[int, Field(ge=1)] | None = None
    poi: str | None = None
    times: Annotated[int, Field(ge=1)] = 1
    result: Literal["failed", "aborted"] = "failed"
    after: NonNegative = 2.0

    @model_validator(mode="after")
    def _one_selector(self) -> NavFailure:
        if (self.goal is None) == (self.poi is None):
            raise ValueError("expected exactly one of goal: N or poi: NAME")
        return self


class LateAnswer(_Model):
    """Hold back the robot's ``/FROG_response`` to goals at ``poi`` (every goal: none) by
    ``delay`` seconds; a newer goal meanwhile does not cancel it, so it arrives after that
    goal went out (a stale answer). ``duplicate``: the final answer is sent twice."""

    poi: str | None = None
    delay: NonNegative = 2.0
    duplicate: bool = False


class NavigationSpec(_Model):
    speed: Positive = 0.6  # m/s, straight line
    approach_time: NonNegative = 3.0  # seconds an /ApproachPeopleFar takes
    failures: list[NavFailure] = []
    late: list[LateAnswer] = []  # answers held back (out of order with newer goals)


class DockingSpec(_Model):
    undock_time: NonNegative = 5.0
    dock_time: NonNegative = 10.0
    undock_failures: Count = 0  # the first K undock attempts end "failed"
    dock_failures: Count = 0
    dock_range: Positive = 2.0  # docking farther than this from the dock fails


class BatterySpec(_Model):
    start: Annotated[float, Field(ge=0, le=100)] = 90.0
    drain_per_hour: NonNegative = 5.0  # percent per hour while undocked
    charge_per_hour: NonNegative = 20.0  # percent per hour while docked


class FaultSpec(_Model):
    """A ``/diagnostic`` status at level 2 (ERROR) or 3 (STALE) from ``at`` on, or from
    the robot's arrival at ``on_arrival`` (a POI, or any of its variants). ``pad_to``:
    the message repeated up to that many characters (a driver's stack trace)."""

    at: NonNegative | None = None
    on_arrival: str | None = None
    name: str
    level: Literal[2, 3] = 2
    message: str = ""
    pad_to: Annotated[int, Field(ge=0, le=1_000_000)] = 0
    duration: Positive | None = None  # seconds; none: the fault stays

    @model_validator(mode="after")
    def _one_start(self) -> FaultSpec:
        if (self.at is None) == (self.on_arrival is None):
            raise ValueError("expected exactly one of at: SECONDS or on_arrival: POI")
        return self

    @property
    def text(self) -> str:
        """The message as the robot publishes it (padded to ``pad_to``)."""
        message = self.message
        if self.pad_to and message:
            message = (message * (self.pad_to // len(message) + 1))[: self.pad_to]
        return message


class WanderSpec(_Model):
    """The visitor stops following when the robot heads to ``heading_to``, or at ``at``."""

    heading_to: str | None = None
    at: NonNegative | None = None

    @model_validator(mode="after")
    def _one_trigger(self) -> WanderSpec:
        if (self.heading_to is None) == (self.at is None):
            raise ValueError("expected exactly one of heading_to: POI or at: SECONDS")
        return self


class VisitorSpec(_Model):
    """A scripted person; see the ``frog-bt sim --help`` text for the meaning of each key."""

    id: Int32
    position: XY
    orientation: Annotated[float, Field(ge=0, le=360)] | None = None
    facing: bool | None = None
    appear_at: NonNegative | None = 0.0  # null or "never": never appears
    approach: list[Outcome] | Outcome = []  # one outcome: every approach ends so
    answer: Literal["positive", "negative"] = "positive"
    faces: str | tuple[float, ...] = "engaged"  # a profile name or values cycled
    follow: bool = True
    wander_off: WanderSpec | None = None
    after_tour: Literal["leave", "stay", "return"] = "leave"

    @field_validator("appear_at", mode="before")
    @classmethod
    def _never(cls, value: Any) -> Any:
        return None if value == "never" else value

    @field_validator("faces", mode="before")
    @classmethod
    def _faces(cls, value: Any) -> str | tuple[float, ...]:
        expected = f"expected one of {', '.join(FACE_PROFILES)}, or a list of numbers in [-1, 1]"
        if isinstance(value, str) and value in FACE_PROFILES:
            return value
        if (
            isinstance(value, list | tuple)
            and value
            and all(
                isinstance(v, int | float)
                and not isinstance(v, bool)
                and math.isfinite(v)
                and -1 <= v <= 1
                for v in value
            )
        ):
            return tuple(float(v) for v in value)
        raise ValueError(f"{expected}, got {value!r}"[:200])

    @model_validator(mode="after")
    def _orientation_or_facing(self) -> VisitorSpec:
        if self.orientation is not None and self.facing is not None:
            raise ValueError(
                "give orientation (degrees, 180 = facing the robot) or facing, not both"
            )
        return self

    @property
    def detected_orientation(self) -> float:
        """Degrees relative to the robot as the camera reports them (180 = facing it)."""
        if self.orientation is not None:
            return self.orientation
        return 90.0 if self.facing is False else 180.0


class FrontendSpec(_Model):
    silent: bool = False  # sends nothing at all: no acks, no events
    # Silent from this time on, or in these [start, end) intervals: hung, it neither
    # sends (no acks, no events) nor acts on commands; due events go out when it wakes.
    silent_from: NonNegative | None = None
    silent_between: list[tuple[NonNegative, NonNegative]] = []
    ack: bool = True  # false: never acks commands, but still plays and answers
    idle_at: NonNegative = 1.0  # first frontend_idle
    idle_after_tour: NonNegative | None = 5.0  # frontend_idle again after tour ended/aborted
    restarts: list[NonNegative] = []  # the front end restarts (seq from 1) and says idle
    answer_delay: NonNegative = 2.0  # ask_tour -> user_positive / user_negative
    # Each datagram, either way, is lost with this probability (seeded by ``seed``).
    loss: Annotated[float, Field(ge=0, le=0.9)] = 0.0
    never_sends: list[Literal[tuple(fm.EVENTS)]] = []  # type: ignore[valid-type]

    @field_validator("silent_between")
    @classmethod
    def _intervals(cls, value: list[tuple[float, float]]) -> list[tuple[float, float]]:
        for i, (start, end) in enumerate(value):
            if not end > start:
                raise PathError(
                    (i,), f"expected [start, end] with end > start, got [{start:g}, {end:g}]"
                )
        return value

    def silences(self) -> list[tuple[float, float]]:
        """Every silent interval, in seconds after the start (end ``inf``: for ever)."""
        out = [(float(a), float(b)) for a, b in self.silent_between]
        if self.silent_from is not None:
            out.append((self.silent_from, math.inf))
        return out


class ContentParts(_Model):
    a: Positive | None = None
    b: Positive | None = None


class Scenario(_Model):
    """A whole simulated mission; every key has a default (an empty file is valid)."""

    name: str = ""
    description: str = ""
    start_time: datetime = DEFAULT_START
    speed: Positive = 50.0
    dt: Annotated[float, Field(gt=0, le=1)] = 0.1
    seed: int = 0
    detection_range: Positive = 15.0
    robot: RobotSpec = RobotSpec()
    navigation: NavigationSpec = NavigationSpec()
    docking: DockingSpec = DockingSpec()
    battery: BatterySpec = BatterySpec()
    faults: list[FaultSpec] = []
    visitors: list[VisitorSpec] = []
    frontend: FrontendSpec = FrontendSpec()
    content: dict[str, Any] = {}

    @field_validator("start_time")
    @classmethod
    def _aware(cls, value: datetime) -> datetime:
        return value if value.tzinfo is not None else value.replace(tzinfo=SITE_TZ)

    @field_validator("content")
    @classmethod
    def _content(cls, value: dict[str, Any]) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, item in value.items():
            if _positive(item):
                out[key] = float(item)
            elif isinstance(item, dict) and key not in ("default", "introduction"):
                for part, seconds in item.items():
                    if part not in ("a", "b"):
                        raise PathError((key, part), 'unknown part; expected "a" or "b"')
                    if seconds is not None and not _positive(seconds):
                        raise PathError((key, part), f"expected seconds > 0, got {seconds!r}"[:200])
                out[key] = ContentParts(**item)
            else:
                what = (
                    "seconds > 0"
                    if key in ("default", "introduction")
                    else "seconds > 0 or {a: seconds, b: seconds}"
                )
                raise PathError((key,), f"expected {what}, got {item!r}"[:200])
        return out

    @model_validator(mode="after")
    def _unique_ids(self) -> Scenario:
        seen: set[int] = set()
        for i, visitor in enumerate(self.visitors):
            if visitor.id in seen:
                raise PathError(("visitors", i, "id"), f"duplicate visitor id {visitor.id}")
            seen.add(visitor.id)
        return self

    @property
    def start_epoch(self) -> float:
        return self.start_time.timestamp()

    @property
    def introduction_seconds(self) -> float:
        return float(self.content.get("introduction", 20.0))

    def content_seconds(self, poi: str, waypoint: str, part: str) -> float:
        """How long the front end plays ``part`` of a POI (by POI, then waypoint, then default)."""
        default = float(self.content.get("default", 30.0))
        for key in (poi, waypoint):
            item = self.content.get(key)
            if isinstance(item, float):
                return item
            if isinstance(item, ContentParts):
                seconds = getattr(item, part, None)
                return default if seconds is None else seconds
        return default


def _positive(value: Any) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and value > 0
    )


# ------------------------------------------------------------------ loading

SCENARIO_DIR = resources.files("frog_bt.sim") / "scenarios"
MAX_EXTENDS = 8


def builtin_scenarios() -> list[str]:
    """Names of the scenarios shipped with frog-bt."""
    return sorted(p.name[:-5] for p in SCENARIO_DIR.iterdir() if p.name.endswith(".yaml"))


def _resolve(path_or_name: str | Path, relative_to: Path | None = None) -> Path:
    text = str(path_or_name)
    builtin = SCENARIO_DIR / f"{text}.yaml"
    looks_like_name = "/" not in text and not text.endswith((".yaml", ".yml"))
    if looks_like_name and builtin.is_file():
        return Path(str(builtin))
    path = Path(text)
    if relative_to is not None and not path.is_absolute():
        path = relative_to / path
    if looks_like_name and not path.exists():
        raise ConfigError(
            text,
            (),
            "no such scenario; expected a built-in name "
            f"({', '.join(builtin_scenarios())}) or a YAML file path",
        )
    return path


def _raw(path: Path, depth: int = 0) -> dict[str, Any]:
    data = load_yaml(path, ConfigError)
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(
            str(path), (), f"expected a mapping of scenario keys, got {type(data).__name__}"
        )
    base_ref = data.pop("extends", None)
    if base_ref is None:
        return data
    if not isinstance(base_ref, str):
        raise ConfigError(str(path), ("extends",), "expected a scenario name or file path")
    if depth >= MAX_EXTENDS:
        raise ConfigError(str(path), ("extends",), f"more than {MAX_EXTENDS} levels of extends")
    base = _raw(_resolve(base_ref, path.parent), depth + 1)
    base.pop("name", None)
    return merge(base, data)


def merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """``over`` on top of ``base``: mappings merge key by key, everything else replaces."""
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


def scenario_from(
    base: str | Path = "default", overrides: dict[str, Any] | None = None
) -> Scenario:
    """Scenario ``base`` with ``overrides`` on top (mappings merge, lists replace)."""
    data = load_scenario(base).model_dump(mode="json")
    return parse_scenario(merge(data, overrides or {}), f"{base} + overrides")


def parse_scenario(data: Any, file: str = "<scenario>") -> Scenario:
    """A :class:`Scenario` from an already-loaded mapping (tests build them this way)."""
    return validate(Scenario, {} if data is None else data, file, ConfigError)


def load_scenario(path_or_name: str | Path) -> Scenario:
    """Load a built-in scenario by name or a scenario YAML file; raises ConfigError."""
    path = _resolve(path_or_name)
    data = _raw(path)
    data.setdefault("name", path.stem)
    return parse_scenario(data, str(path))
