"""The ROS messages that cross the rosbridge link (CONTRACT §1), as msgspec Structs.

Each ROS type has a *wire* Struct, field for field as rosbridge sends it, with the
ranges the executive relies on (finite numbers, int32 ids, engagement in
[-1, 1], ...), and a *value*: what the blackboard and the leaves see. A wire
Struct's ``value()`` gives the value and its ``of(value)`` builds the wire form
back, so one class is the decoder, the encoder (executive and simulator) and,
through ``msgspec.json.schema``, the recording's JSON schema. :data:`ROS_TYPES`
lists them by ROS type name.

Times are accepted in the ROS 1 (``{secs, nsecs}``) and ROS 2 (``{sec,
nanosec}``) shapes and sent in the ROS 1 shape, as CONTRACT §1 asks. A missing
header reads as stamp 0 and no frame.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Annotated, Any, ClassVar, Generic, Protocol, TypeVar

import msgspec

from frog_bt.codec import Finite, Int32, UInt32, convert, decoder, encode
from frog_bt.errors import DecodeError
from frog_bt.text import FIELD, MESSAGE, inert

V = TypeVar("V")

# ---------------------------------------------------------------- time and header


class Time(msgspec.Struct, frozen=True, omit_defaults=True):
    """``time``: ROS 1 ``{secs, nsecs}`` or ROS 2 ``{sec, nanosec}``."""

    secs: int | None = None
    nsecs: int | None = None
    sec: int | None = None
    nanosec: int | None = None

    def __post_init__(self) -> None:
        if self.secs is not None and self.nsecs is not None:
            secs, nsecs = self.secs, self.nsecs
        elif self.sec is not None and self.nanosec is not None:
            secs, nsecs = self.sec, self.nanosec
        else:
            raise ValueError("expected {secs, nsecs} or {sec, nanosec}")
        if not 0 <= nsecs < 1_000_000_000:
            raise ValueError(f"nanoseconds {nsecs} out of range")
        if not -(2**31) <= secs < 2**32:  # ROS 1 secs is uint32, ROS 2 sec int32
            raise ValueError(f"seconds {secs} out of range")

    @property
    def seconds(self) -> float:
        if self.secs is not None:
            return self.secs + self.nsecs * 1e-9  # type: ignore[operator]
        return self.sec + self.nanosec * 1e-9  # type: ignore[operator]


def encode_time(t: float) -> Time:
    """ROS 1 time to the microsecond: an epoch time as a float is only good to about
    0.2 µs, so 10:30:00.1 would otherwise read 10:30:00.099999905. The one time encoder
    (the simulator uses it too)."""
    secs = math.floor(t)
    usecs = round((t - secs) * 1e6)
    if usecs >= 1_000_000:
        secs, usecs = secs + 1, 0
    if secs >= 2**32:  # a float just below 2**32 rounds to it: the last instant uint32 holds
        return Time(secs=2**32 - 1, nsecs=999_999_999)
    return Time(secs=int(secs), nsecs=int(usecs) * 1000)


ZERO = Time(secs=0, nsecs=0)


class Header(msgspec.Struct, frozen=True):
    seq: UInt32 = 0
    stamp: Time = ZERO
    frame_id: str = ""


def header(t: float, frame_id: str = "", seq: int = 0) -> Header:
    return Header(seq, encode_time(t), frame_id)


NO_HEADER = Header()

# ---------------------------------------------------------------- elements (wire = value)


class Point(msgspec.Struct, frozen=True):
    x: Finite
    y: Finite
    z: Finite = 0.0


class Quaternion(msgspec.Struct, frozen=True, kw_only=True):
    x: Finite = 0.0
    y: Finite = 0.0
    z: Finite = 0.0
    w: Finite


class PersonDetection(msgspec.Struct, frozen=True):
    id: Int32
    position: Point
    # degrees 0..360 relative to the robot, 180 = facing it
    orientation: Annotated[float, msgspec.Meta(ge=0.0, le=360.0)]


class Face(msgspec.Struct, frozen=True):
    id: Int32
    engagement: Annotated[float, msgspec.Meta(ge=-1.0, le=1.0)]
    distance: Annotated[float, msgspec.Meta(ge=0.0, le=sys.float_info.max)]  # metres
    facing: bool


class TrackedPerson(msgspec.Struct, frozen=True):
    id: Int32
    position: Point


class KeyValue(msgspec.Struct, frozen=True):
    key: str
    value: str


class DiagnosticStatus(msgspec.Struct, frozen=True):
    """``diagnostic_msgs/DiagnosticStatus``: level 0 OK, 1 WARN, 2 ERROR, 3 STALE."""

    level: Annotated[int, msgspec.Meta(ge=0, le=3)]
    name: str
    message: str = ""
    hardware_id: str = ""
    values: tuple[KeyValue, ...] = ()


# ---------------------------------------------------------------- values


@dataclass(frozen=True, slots=True)
class Pose:
    """Robot pose in the map frame (``geometry_msgs/PoseStamped``)."""

    stamp: float
    frame_id: str
    x: float
    y: float
    qz: float
    qw: float

    @property
    def yaw(self) -> float:
        return 2.0 * math.atan2(self.qz, self.qw)


@dataclass(frozen=True, slots=True)
class Diagnostics:
    """What the executive needs of a ``diagnostic_msgs/DiagnosticArray``.

    ``faults`` lists ``name: message`` of every status at level 2 (ERROR) or
    3 (STALE); ``battery`` is the ``percentage`` of status ``battery``, if any.
    """

    stamp: float
    battery: float | None
    faults: tuple[str, ...]
    statuses: tuple[DiagnosticStatus, ...] = field(default=(), compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class PersonDetections:
    stamp: float
    persons: tuple[PersonDetection, ...]


@dataclass(frozen=True, slots=True)
class FaceData:
    stamp: float
    faces: tuple[Face, ...]


@dataclass(frozen=True, slots=True)
class TrackedPeople:
    stamp: float
    people: tuple[TrackedPerson, ...]


# ---------------------------------------------------------------- wire messages


class PoseBody(msgspec.Struct, frozen=True):
    position: Point
    orientation: Quaternion


class PoseStamped(msgspec.Struct, frozen=True, kw_only=True):
    ros_type: ClassVar[str] = "geometry_msgs/PoseStamped"
    header: Header = NO_HEADER
    pose: PoseBody

    def value(self) -> Pose:
        p, q = self.pose.position, self.pose.orientation
        return Pose(self.header.stamp.seconds, self.header.frame_id, p.x, p.y, q.z, q.w)

    @classmethod
    def of(cls, pose: Pose) -> PoseStamped:
        return cls(
            header=header(pose.stamp, pose.frame_id),
            pose=PoseBody(Point(pose.x, pose.y), Quaternion(z=pose.qz, w=pose.qw)),
        )


class Int32Msg(msgspec.Struct, frozen=True):
    ros_type: ClassVar[str] = "std_msgs/Int32"
    data: Int32

    def value(self) -> int:
        return self.data

    @classmethod
    def of(cls, value: int) -> Int32Msg:
        return cls(int(value))


class StringMsg(msgspec.Struct, frozen=True):
    ros_type: ClassVar[str] = "std_msgs/String"
    data: str

    def value(self) -> str:
        return inert(self.data, FIELD)  # robot text (a docking state): bounded and inert

    @classmethod
    def of(cls, value: str) -> StringMsg:
        return cls(value)


class DiagnosticArray(msgspec.Struct, frozen=True, kw_only=True):
    ros_type: ClassVar[str] = "diagnostic_msgs/DiagnosticArray"
    header: Header = NO_HEADER
    status: tuple[DiagnosticStatus, ...]

    def value(self) -> Diagnostics:
        battery: float | None = None
        faults: list[str] = []
        for i, status in enumerate(self.status):
            if status.level >= 2:
                name = inert(status.name, FIELD)  # robot text: bounded and inert from here on
                message = inert(status.message, MESSAGE)
                faults.append(f"{name}: {message}" if message else name)
            if status.name == "battery":
                for j, kv in enumerate(status.values):
                    if kv.key == "percentage":
                        battery = _percentage(kv.value, ("status", i, "values", j, "value"))
        return Diagnostics(self.header.stamp.seconds, battery, tuple(faults), self.status)

    @classmethod
    def of(cls, value: Diagnostics) -> DiagnosticArray:
        return cls(header=header(value.stamp), status=value.statuses)


def _percentage(text: str, path: tuple[str | int, ...]) -> float:
    try:
        pct = float(text)
    except ValueError:
        raise DecodeError(f"expected a number, got {text[:40]!r}", path) from None
    if not math.isfinite(pct):
        raise DecodeError(f"expected a finite number, got {text!r}", path)
    return pct


class PersonDetectionsMsg(msgspec.Struct, frozen=True, kw_only=True):
    ros_type: ClassVar[str] = "frog_msgs/PersonDetections"
    header: Header = NO_HEADER
    persons: tuple[PersonDetection, ...]

    def value(self) -> PersonDetections:
        return PersonDetections(self.header.stamp.seconds, self.persons)

    @classmethod
    def of(cls, value: PersonDetections) -> PersonDetectionsMsg:
        return cls(header=header(value.stamp, "map"), persons=tuple(value.persons))


class FaceDataMsg(msgspec.Struct, frozen=True, kw_only=True):
    ros_type: ClassVar[str] = "frog_msgs/FaceData"
    header: Header = NO_HEADER
    faces: tuple[Face, ...]

    def value(self) -> FaceData:
        return FaceData(self.header.stamp.seconds, self.faces)

    @classmethod
    def of(cls, value: FaceData) -> FaceDataMsg:
        return cls(header=header(value.stamp), faces=tuple(value.faces))


class TrackedPeopleMsg(msgspec.Struct, frozen=True, kw_only=True):
    ros_type: ClassVar[str] = "frog_msgs/TrackedPeople"
    header: Header = NO_HEADER
    people: tuple[TrackedPerson, ...]

    def value(self) -> TrackedPeople:
        return TrackedPeople(self.header.stamp.seconds, self.people)

    @classmethod
    def of(cls, value: TrackedPeople) -> TrackedPeopleMsg:
        return cls(header=header(value.stamp, "map"), people=tuple(value.people))


class ClockMsg(msgspec.Struct, frozen=True):
    ros_type: ClassVar[str] = "rosgraph_msgs/Clock"
    clock: Time

    def value(self) -> float:
        return self.clock.seconds

    @classmethod
    def of(cls, t: float) -> ClockMsg:
        return cls(encode_time(t))


# ---------------------------------------------------------------- codecs by ROS type


class Wire(Protocol[V]):
    """What a wire Struct has: its ROS type name, its ``value()``, and ``of(value)``."""

    ros_type: ClassVar[str]

    def value(self) -> V: ...

    @classmethod
    def of(cls, value: V, /) -> Wire[V]: ...


class RosType(Generic[V]):
    """One ROS type's codec: ``decode`` (a rosbridge ``msg``, as JSON text) and
    ``convert`` (the same as Python objects) give the value or raise DecodeError;
    ``encode`` gives the ``msg`` object of a value; ``schema`` its JSON schema."""

    def __init__(self, wire: type[Wire[V]]) -> None:
        self.name: str = wire.ros_type
        self.wire = wire
        self._decode = decoder(wire)

    def decode(self, raw: bytes | str) -> V:
        return self._decode(raw).value()

    def convert(self, obj: Any) -> V:
        return convert(obj, self.wire).value()

    def encode(self, value: V) -> dict[str, Any]:
        """The ``msg`` object (JSON types: lists, not tuples)."""
        msg: dict[str, Any] = msgspec.json.decode(encode(self.wire.of(value)))  # NaN: ValueError
        return msg

    def schema(self) -> dict[str, Any]:
        return msgspec.json.schema(self.wire)

    def __repr__(self) -> str:
        return f"RosType({self.name})"


POSE: RosType[Pose] = RosType(PoseStamped)
INT32: RosType[int] = RosType(Int32Msg)
STRING: RosType[str] = RosType(StringMsg)
DIAGNOSTICS: RosType[Diagnostics] = RosType(DiagnosticArray)
PERSONS: RosType[PersonDetections] = RosType(PersonDetectionsMsg)
FACES: RosType[FaceData] = RosType(FaceDataMsg)
PEOPLE: RosType[TrackedPeople] = RosType(TrackedPeopleMsg)
CLOCK: RosType[float] = RosType(ClockMsg)

ROS_TYPES: dict[str, RosType[Any]] = {
    t.name: t for t in (POSE, INT32, STRING, DIAGNOSTICS, PERSONS, FACES, PEOPLE, CLOCK)
}
