"""The ``msg`` objects the simulated robot publishes, built by the wire codecs.

Each builder returns the JSON a rosbridge server sends for that ROS message, as
:mod:`frog_bt.model.ros` encodes it (the executive decodes with the same
classes, so ``decode(encode(x)) == x``). Items may be the element Structs
(:class:`~frog_bt.model.ros.PersonDetection`, :class:`~frog_bt.model.ros.Face`,
:class:`~frog_bt.model.ros.TrackedPerson`, :class:`~frog_bt.model.ros.DiagnosticStatus`)
or mappings with the same keys; a position may be an ``(x, y[, z])`` pair, and
diagnostic ``values`` ``(key, value)`` pairs.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, TypeVar

from frog_bt.codec import convert
from frog_bt.model.ros import (
    CLOCK,
    DIAGNOSTICS,
    FACES,
    PEOPLE,
    PERSONS,
    POSE,
    Diagnostics,
    DiagnosticStatus,
    Face,
    FaceData,
    PersonDetection,
    PersonDetections,
    Pose,
    TrackedPeople,
    TrackedPerson,
)

__all__ = [
    "DiagnosticStatus",
    "clock",
    "diagnostic_array",
    "face_data",
    "person_detections",
    "pose_stamped",
    "tracked_people",
]

S = TypeVar("S")


def _item(cls: type[S], item: Any) -> S:
    if isinstance(item, cls):
        return item
    obj = dict(item)
    if isinstance(obj.get("position"), tuple | list):
        obj["position"] = dict(zip("xyz", obj["position"], strict=False))
    if "values" in obj:
        obj["values"] = [
            dict(zip(("key", "value"), kv, strict=True)) if not isinstance(kv, Mapping) else kv
            for kv in obj["values"]
        ]
    return convert(obj, cls)


def person_detections(stamp: float, persons: Iterable[Any]) -> dict[str, Any]:
    """``frog_msgs/PersonDetections``: ``{header, persons: [{id, position, orientation}]}``."""
    return PERSONS.encode(
        PersonDetections(stamp, tuple(_item(PersonDetection, p) for p in persons))
    )


def face_data(stamp: float, faces: Iterable[Any]) -> dict[str, Any]:
    """``frog_msgs/FaceData``: ``{header, faces: [{id, engagement, distance, facing}]}``."""
    return FACES.encode(FaceData(stamp, tuple(_item(Face, f) for f in faces)))


def tracked_people(stamp: float, people: Iterable[Any]) -> dict[str, Any]:
    """``frog_msgs/TrackedPeople``: ``{header, people: [{id, position}]}``."""
    return PEOPLE.encode(TrackedPeople(stamp, tuple(_item(TrackedPerson, p) for p in people)))


def diagnostic_array(stamp: float, statuses: Iterable[Any]) -> dict[str, Any]:
    """``diagnostic_msgs/DiagnosticArray``: ``{header, status: [DiagnosticStatus]}``."""
    items = tuple(_item(DiagnosticStatus, s) for s in statuses)
    return DIAGNOSTICS.encode(Diagnostics(stamp, None, (), items))


def pose_stamped(x: float, y: float, qz: float, qw: float, t: float) -> dict[str, Any]:
    """``geometry_msgs/PoseStamped`` in the map frame."""
    return POSE.encode(Pose(t, "map", x, y, qz, qw))


def clock(t: float) -> dict[str, Any]:
    """``rosgraph_msgs/Clock``: ``{clock: {secs, nsecs}}``."""
    return CLOCK.encode(t)
