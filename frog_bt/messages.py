"""ROS message values that cross the rosbridge link, as typed dataclasses.

Decoders take the ``msg`` JSON object of a rosbridge ``publish`` and return a
frozen dataclass, or raise :class:`~frog_bt.errors.DecodeError` naming the field
(``pose.position.x: expected a finite number, got 'abc'``). They never raise
anything else. Encoders build the ``msg`` objects the executive sends (ROS 1
time shape, as CONTRACT §1 asks).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from frog_bt.errors import DecodeError

Path = tuple[str | int, ...]

# ---------------------------------------------------------------- field readers


def _obj(value: Any, path: Path) -> Mapping[str, Any]:
    if not isinstance(value, dict):
        raise DecodeError(f"expected an object, got {type(value).__name__}", path)
    return value


def _field(obj: Mapping[str, Any], key: str, path: Path) -> Any:
    if key not in obj:
        raise DecodeError("missing field", (*path, key))
    return obj[key]


def _float(obj: Mapping[str, Any], key: str, path: Path, default: float | None = None) -> float:
    if default is not None and key not in obj:
        return default
    value = _field(obj, key, path)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DecodeError(f"expected a number, got {type(value).__name__}", (*path, key))
    try:
        value = float(value)
    except OverflowError:  # a JSON integer beyond float range (1e400 written out)
        raise DecodeError("expected a finite number, got a huge integer", (*path, key)) from None
    if not math.isfinite(value):
        raise DecodeError(f"expected a finite number, got {value}", (*path, key))
    return value


def _int(obj: Mapping[str, Any], key: str, path: Path) -> int:
    value = _field(obj, key, path)
    if isinstance(value, bool) or not isinstance(value, int):
        raise DecodeError(f"expected an integer, got {type(value).__name__}", (*path, key))
    if not -(2**31) <= value < 2**31:
        raise DecodeError(f"integer {value} does not fit int32", (*path, key))
    return value


def _str(obj: Mapping[str, Any], key: str, path: Path, default: str | None = None) -> str:
    if default is not None and key not in obj:
        return default
    value = _field(obj, key, path)
    if not isinstance(value, str):
        raise DecodeError(f"expected a string, got {type(value).__name__}", (*path, key))
    return value


def _bool(obj: Mapping[str, Any], key: str, path: Path) -> bool:
    value = _field(obj, key, path)
    if not isinstance(value, bool):
        raise DecodeError(f"expected a boolean, got {type(value).__name__}", (*path, key))
    return value


def _list(obj: Mapping[str, Any], key: str, path: Path) -> list[Any]:
    value = _field(obj, key, path)
    if not isinstance(value, list):
        raise DecodeError(f"expected a list, got {type(value).__name__}", (*path, key))
    return value


# ---------------------------------------------------------------- time


def decode_time(value: Any, path: Path = ()) -> float:
    """Seconds from ``{"secs", "nsecs"}`` (ROS 1) or ``{"sec", "nanosec"}`` (ROS 2)."""
    obj = _obj(value, path)
    if "secs" in obj:
        secs, nsecs = _int_any(obj, "secs", path), _int_any(obj, "nsecs", path)
    elif "sec" in obj:
        secs, nsecs = _int_any(obj, "sec", path), _int_any(obj, "nanosec", path)
    else:
        raise DecodeError("expected {secs, nsecs} or {sec, nanosec}", path)
    if not 0 <= nsecs < 1_000_000_000:
        raise DecodeError(f"nanoseconds {nsecs} out of range", path)
    # ROS 1 secs is uint32, ROS 2 sec int32; beyond both, float() would overflow.
    if not -(2**31) <= secs < 2**32:
        raise DecodeError(f"seconds {secs} out of range", path)
    return secs + nsecs * 1e-9


def _int_any(obj: Mapping[str, Any], key: str, path: Path) -> int:
    value = _field(obj, key, path)
    if isinstance(value, bool) or not isinstance(value, int):
        raise DecodeError(f"expected an integer, got {type(value).__name__}", (*path, key))
    return value


def encode_time(t: float) -> dict[str, int]:
    """ROS 1 time shape ``{secs, nsecs}``, which CONTRACT §1 says the executive sends,
    to the microsecond: an epoch time as a float is only good to about 0.2 µs, so
    10:30:00.1 would otherwise read 10:30:00.099999905. The one time encoder (the
    simulator uses it too)."""
    secs = math.floor(t)
    usecs = round((t - secs) * 1e6)
    if usecs >= 1_000_000:
        secs, usecs = secs + 1, 0
    return {"secs": int(secs), "nsecs": int(usecs) * 1000}


def _header(obj: Mapping[str, Any], path: Path) -> tuple[float, str]:
    """(stamp, frame_id) of an optional header; a missing header reads as (0, "")."""
    if "header" not in obj:
        return 0.0, ""
    header = _obj(obj["header"], (*path, "header"))
    stamp = decode_time(header["stamp"], (*path, "header", "stamp")) if "stamp" in header else 0.0
    return stamp, _str(header, "frame_id", (*path, "header"), default="")


# ---------------------------------------------------------------- values


@dataclass(frozen=True, slots=True)
class Point:
    x: float
    y: float
    z: float = 0.0


def _point(value: Any, path: Path) -> Point:
    obj = _obj(value, path)
    return Point(_float(obj, "x", path), _float(obj, "y", path), _float(obj, "z", path, 0.0))


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


def _decode_pose_checked(msg: Any) -> Pose:
    obj = _obj(msg, ())
    stamp, frame = _header(obj, ())
    pose = _obj(_field(obj, "pose", ()), ("pose",))
    pos = _point(_field(pose, "position", ("pose",)), ("pose", "position"))
    path: Path = ("pose", "orientation")
    ori = _obj(_field(pose, "orientation", ("pose",)), path)
    return Pose(stamp, frame, pos.x, pos.y, _float(ori, "z", path, 0.0), _float(ori, "w", path))


def encode_pose(x: float, y: float, qz: float, qw: float, stamp: float, frame: str = "map") -> dict:
    return {
        "header": {"seq": 0, "stamp": encode_time(stamp), "frame_id": frame},
        "pose": {
            "position": {"x": x, "y": y, "z": 0.0},
            "orientation": {"x": 0.0, "y": 0.0, "z": qz, "w": qw},
        },
    }


def decode_int32(msg: Any) -> int:
    return _int(_obj(msg, ()), "data", ())


def encode_int32(value: int) -> dict:
    return {"data": int(value)}


def decode_string(msg: Any) -> str:
    return _str(_obj(msg, ()), "data", ())


def encode_string(value: str) -> dict:
    return {"data": value}


@dataclass(frozen=True, slots=True)
class Diagnostics:
    """What the executive needs of a ``diagnostic_msgs/DiagnosticArray``.

    ``faults`` lists ``name: message`` of every status at level 2 (ERROR) or
    3 (STALE); ``battery`` is the ``percentage`` of status ``battery``, if any.
    """

    stamp: float
    battery: float | None
    faults: tuple[str, ...]


def decode_diagnostics(msg: Any) -> Diagnostics:
    obj = _obj(msg, ())
    stamp, _ = _header(obj, ())
    battery: float | None = None
    faults: list[str] = []
    for i, item in enumerate(_list(obj, "status", ())):
        path: Path = ("status", i)
        status = _obj(item, path)
        level = _level(status, path)
        name = _str(status, "name", path)
        message = _str(status, "message", path, default="")
        if level >= 2:
            faults.append(f"{name}: {message}" if message else name)
        values = _list(status, "values", path) if "values" in status else []
        for j, kv in enumerate(values):
            kv_path: Path = (*path, "values", j)
            kv_obj = _obj(kv, kv_path)
            key, text = _str(kv_obj, "key", kv_path), _str(kv_obj, "value", kv_path)
            if name == "battery" and key == "percentage":
                battery = _percentage(text, (*kv_path, "value"))
    return Diagnostics(stamp, battery, tuple(faults))


def _percentage(text: str, path: Path) -> float:
    try:
        pct = float(text)
    except ValueError:
        raise DecodeError(f"expected a number, got {text[:40]!r}", path) from None
    if not math.isfinite(pct):
        raise DecodeError(f"expected a finite number, got {text!r}", path)
    return pct


def _level(status: Mapping[str, Any], path: Path) -> int:
    # rosbridge serialises the uint8/byte ``level`` as an integer.
    level = _int(status, "level", path)
    if not 0 <= level <= 3:
        raise DecodeError(f"expected a level 0..3, got {level}", (*path, "level"))
    return level


@dataclass(frozen=True, slots=True)
class PersonDetection:
    id: int
    position: Point
    orientation: float  # degrees 0..360 relative to the robot, 180 = facing it


@dataclass(frozen=True, slots=True)
class PersonDetections:
    stamp: float
    persons: tuple[PersonDetection, ...]


def _decode_person_detections_checked(msg: Any) -> PersonDetections:
    obj = _obj(msg, ())
    stamp, _ = _header(obj, ())
    persons = []
    for i, item in enumerate(_list(obj, "persons", ())):
        path: Path = ("persons", i)
        p = _obj(item, path)
        orientation = _float(p, "orientation", path)
        if not 0.0 <= orientation <= 360.0:
            raise DecodeError(f"expected degrees in [0, 360], got {orientation}",
                              (*path, "orientation"))
        persons.append(PersonDetection(
            _int(p, "id", path), _point(_field(p, "position", path), (*path, "position")),
            orientation))
    return PersonDetections(stamp, tuple(persons))


@dataclass(frozen=True, slots=True)
class Face:
    id: int
    engagement: float  # -1 .. 1
    distance: float  # metres
    facing: bool


@dataclass(frozen=True, slots=True)
class FaceData:
    stamp: float
    faces: tuple[Face, ...]


def _decode_face_data_checked(msg: Any) -> FaceData:
    obj = _obj(msg, ())
    stamp, _ = _header(obj, ())
    faces = []
    for i, item in enumerate(_list(obj, "faces", ())):
        path: Path = ("faces", i)
        f = _obj(item, path)
        engagement = _float(f, "engagement", path)
        if not -1.0 <= engagement <= 1.0:
            raise DecodeError(f"expected engagement in [-1, 1], got {engagement}",
                              (*path, "engagement"))
        distance = _float(f, "distance", path)
        if distance < 0:
            raise DecodeError(f"expected a distance >= 0, got {distance}", (*path, "distance"))
        faces.append(Face(_int(f, "id", path), engagement, distance, _bool(f, "facing", path)))
    return FaceData(stamp, tuple(faces))


@dataclass(frozen=True, slots=True)
class TrackedPerson:
    id: int
    position: Point


@dataclass(frozen=True, slots=True)
class TrackedPeople:
    stamp: float
    people: tuple[TrackedPerson, ...]


def _decode_tracked_people_checked(msg: Any) -> TrackedPeople:
    obj = _obj(msg, ())
    stamp, _ = _header(obj, ())
    people = []
    for i, item in enumerate(_list(obj, "people", ())):
        path: Path = ("people", i)
        p = _obj(item, path)
        people.append(TrackedPerson(
            _int(p, "id", path), _point(_field(p, "position", path), (*path, "position"))))
    return TrackedPeople(stamp, tuple(people))


def decode_clock(msg: Any) -> float:
    obj = _obj(msg, ())
    return decode_time(_field(obj, "clock", ()), ("clock",))


def encode_clock(t: float) -> dict:
    return {"clock": encode_time(t)}


# ---------------------------------------------------------------- fast paths
#
# The decoders below run for every inbound message (poses at 10 Hz, faces, detections).
# Each first tries a straight read of a well-formed message: exact JSON types (a float
# where a float is due, an int where an int), no field-by-field paths. Whatever that read
# does not accept, including everything malformed, goes through the checked decoder
# above, which gives the same value or the DecodeError naming the field. The fast read
# accepts only what the checked one accepts, and builds the same value from it.

_INT32_MIN, _INT32_MAX = -(2**31), 2**31


def _fast_float(obj: dict, key: str) -> float | None:
    v = obj[key]
    return v if type(v) is float and v - v == 0.0 else None  # finite: inf - inf is NaN


def _fast_opt_float(obj: dict, key: str) -> float | None:
    if key not in obj:
        return 0.0
    v = obj[key]
    return v if type(v) is float and v - v == 0.0 else None


def _fast_int32(obj: dict, key: str) -> int | None:
    v = obj[key]
    return v if type(v) is int and _INT32_MIN <= v < _INT32_MAX else None


def _fast_header(obj: dict) -> tuple[float, str] | None:
    if "header" not in obj:
        return 0.0, ""
    header = obj["header"]
    if type(header) is not dict:
        return None
    frame = header.get("frame_id", "")
    if type(frame) is not str:
        return None
    if "stamp" not in header:
        return 0.0, frame
    stamp = header["stamp"]
    if type(stamp) is not dict:
        return None
    if "secs" in stamp:
        secs, nsecs = stamp["secs"], stamp["nsecs"]
    elif "sec" in stamp:
        secs, nsecs = stamp["sec"], stamp["nanosec"]
    else:
        return None
    if (type(secs) is int and type(nsecs) is int and 0 <= nsecs < 1_000_000_000
            and -(2**31) <= secs < 2**32):
        return secs + nsecs * 1e-9, frame
    return None


def _fast_point(value: Any) -> Point | None:
    if type(value) is not dict:
        return None
    x, y, z = _fast_float(value, "x"), _fast_float(value, "y"), _fast_opt_float(value, "z")
    if x is None or y is None or z is None:
        return None
    return Point(x, y, z)


def decode_pose(msg: Any) -> Pose:
    try:
        if type(msg) is dict:
            head = _fast_header(msg)
            pose = msg["pose"]
            pos, ori = _fast_point(pose["position"]), pose["orientation"]
            if head is not None and pos is not None and type(ori) is dict:
                qz, qw = _fast_opt_float(ori, "z"), _fast_float(ori, "w")
                if qz is not None and qw is not None:
                    return Pose(head[0], head[1], pos.x, pos.y, qz, qw)
    except (KeyError, TypeError):
        pass
    return _decode_pose_checked(msg)


def decode_face_data(msg: Any) -> FaceData:
    try:
        if type(msg) is dict and type(msg["faces"]) is list:
            head = _fast_header(msg)
            faces = []
            for f in msg["faces"]:
                if type(f) is not dict:
                    break
                e, d, i, facing = (_fast_float(f, "engagement"), _fast_float(f, "distance"),
                                   _fast_int32(f, "id"), f["facing"])
                if (e is None or not -1.0 <= e <= 1.0 or d is None or d < 0 or i is None
                        or type(facing) is not bool):
                    break
                faces.append(Face(i, e, d, facing))
            else:
                if head is not None:
                    return FaceData(head[0], tuple(faces))
    except (KeyError, TypeError):
        pass
    return _decode_face_data_checked(msg)


def decode_person_detections(msg: Any) -> PersonDetections:
    try:
        if type(msg) is dict and type(msg["persons"]) is list:
            head = _fast_header(msg)
            persons = []
            for p in msg["persons"]:
                if type(p) is not dict:
                    break
                o, i, pos = _fast_float(p, "orientation"), _fast_int32(p, "id"), \
                    _fast_point(p["position"])
                if o is None or not 0.0 <= o <= 360.0 or i is None or pos is None:
                    break
                persons.append(PersonDetection(i, pos, o))
            else:
                if head is not None:
                    return PersonDetections(head[0], tuple(persons))
    except (KeyError, TypeError):
        pass
    return _decode_person_detections_checked(msg)


def decode_tracked_people(msg: Any) -> TrackedPeople:
    try:
        if type(msg) is dict and type(msg["people"]) is list:
            head = _fast_header(msg)
            people = []
            for p in msg["people"]:
                if type(p) is not dict:
                    break
                i, pos = _fast_int32(p, "id"), _fast_point(p["position"])
                if i is None or pos is None:
                    break
                people.append(TrackedPerson(i, pos))
            else:
                if head is not None:
                    return TrackedPeople(head[0], tuple(people))
    except (KeyError, TypeError):
        pass
    return _decode_tracked_people_checked(msg)


# ROS type name -> decoder; the subscriber side looks decoders up by type.
DECODERS: dict[str, Callable[[Any], Any]] = {
    "geometry_msgs/PoseStamped": decode_pose,
    "std_msgs/Int32": decode_int32,
    "std_msgs/String": decode_string,
    "diagnostic_msgs/DiagnosticArray": decode_diagnostics,
    "frog_msgs/PersonDetections": decode_person_detections,
    "frog_msgs/FaceData": decode_face_data,
    "frog_msgs/TrackedPeople": decode_tracked_people,
    "rosgraph_msgs/Clock": decode_clock,
}
