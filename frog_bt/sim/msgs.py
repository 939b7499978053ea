"""The ``msg`` objects the simulated robot publishes, field for field as the ROS types.

Each builder returns the JSON a rosbridge server would send for that ROS
message: every field of the ``.msg`` definition (CONTRACT §1 and ``ros/``),
with JSON types matching the ROS ones (int32 -> int, float32 -> float,
bool -> bool, ``geometry_msgs/Point`` -> ``{x, y, z}`` floats,
``std_msgs/Header`` -> ``{seq, stamp: {secs, nsecs}, frame_id}``).

Items may be the value dataclasses of :mod:`frog_bt.messages`
(:class:`~frog_bt.messages.PersonDetection`, :class:`~frog_bt.messages.Face`,
:class:`~frog_bt.messages.TrackedPerson`) or mappings with the same keys, so
that ``decode_x(x(stamp, items))`` gives the items back.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from frog_bt.messages import encode_pose, encode_time

__all__ = [
    "DiagnosticStatus",
    "clock",
    "diagnostic_array",
    "face_data",
    "header",
    "person_detections",
    "pose_stamped",
    "tracked_people",
]


@dataclass(frozen=True, slots=True)
class DiagnosticStatus:
    """One ``diagnostic_msgs/DiagnosticStatus``: level 0 OK, 1 WARN, 2 ERROR, 3 STALE."""

    level: int
    name: str
    message: str = ""
    hardware_id: str = "frog"
    values: tuple[tuple[str, str], ...] = ()


def header(t: float, frame_id: str = "", seq: int = 0) -> dict[str, Any]:
    """``std_msgs/Header`` (ROS 1 time shape)."""
    return {"seq": int(seq), "stamp": encode_time(t), "frame_id": frame_id}


def _get(item: Any, name: str) -> Any:
    return item[name] if isinstance(item, Mapping) else getattr(item, name)


def _point(value: Any) -> dict[str, float]:
    if isinstance(value, Mapping):
        return {"x": float(value["x"]), "y": float(value["y"]), "z": float(value.get("z", 0.0))}
    if isinstance(value, tuple | list):
        z = value[2] if len(value) > 2 else 0.0
        return {"x": float(value[0]), "y": float(value[1]), "z": float(z)}
    return {"x": float(value.x), "y": float(value.y), "z": float(getattr(value, "z", 0.0))}


def person_detections(stamp: float, persons: Iterable[Any], frame_id: str = "map",
                      seq: int = 0) -> dict[str, Any]:
    """``frog_msgs/PersonDetections``: ``{header, persons: [{id, position, orientation}]}``."""
    return {
        "header": header(stamp, frame_id, seq),
        "persons": [{"id": int(_get(p, "id")), "position": _point(_get(p, "position")),
                     "orientation": float(_get(p, "orientation"))} for p in persons],
    }


def face_data(stamp: float, faces: Iterable[Any], frame_id: str = "",
              seq: int = 0) -> dict[str, Any]:
    """``frog_msgs/FaceData``: ``{header, faces: [{id, engagement, distance, facing}]}``."""
    return {
        "header": header(stamp, frame_id, seq),
        "faces": [{"id": int(_get(f, "id")), "engagement": float(_get(f, "engagement")),
                   "distance": float(_get(f, "distance")), "facing": bool(_get(f, "facing"))}
                  for f in faces],
    }


def tracked_people(stamp: float, people: Iterable[Any], frame_id: str = "map",
                   seq: int = 0) -> dict[str, Any]:
    """``frog_msgs/TrackedPeople``: ``{header, people: [{id, position}]}``."""
    return {
        "header": header(stamp, frame_id, seq),
        "people": [{"id": int(_get(p, "id")), "position": _point(_get(p, "position"))}
                   for p in people],
    }


def diagnostic_array(stamp: float, statuses: Iterable[Any], seq: int = 0) -> dict[str, Any]:
    """``diagnostic_msgs/DiagnosticArray``: ``{header, status: [DiagnosticStatus]}``.

    ``values`` of a status are ``(key, value)`` pairs or ``{key, value}`` mappings;
    both become ``diagnostic_msgs/KeyValue`` objects with string fields.
    """
    out = []
    for s in statuses:
        values = []
        for kv in _get(s, "values"):
            key, value = (kv["key"], kv["value"]) if isinstance(kv, Mapping) else kv
            values.append({"key": str(key), "value": str(value)})
        out.append({"level": int(_get(s, "level")), "name": str(_get(s, "name")),
                    "message": str(_get(s, "message")),
                    "hardware_id": str(_get(s, "hardware_id")), "values": values})
    return {"header": header(stamp, "", seq), "status": out}


def pose_stamped(x: float, y: float, qz: float, qw: float, t: float) -> dict[str, Any]:
    """``geometry_msgs/PoseStamped`` in the map frame."""
    return {**encode_pose(x, y, qz, qw, t, "map"), "header": header(t, "map")}


def clock(t: float) -> dict[str, Any]:
    """``rosgraph_msgs/Clock``: ``{clock: {secs, nsecs}}``."""
    return {"clock": encode_time(t)}
