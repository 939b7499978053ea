"""Test shorthands for the ROS codecs of :mod:`frog_bt.model.ros`: decoders of
``msg`` objects (or raw JSON) by name, and encoders with the old positional forms."""

from __future__ import annotations

from typing import Any

import msgspec

from frog_bt.model.ros import (
    CLOCK,
    DIAGNOSTICS,
    FACES,
    INT32,
    PEOPLE,
    PERSONS,
    POSE,
    ROS_TYPES,
    STRING,
    Pose,
    RosType,
)


def _decoder(codec: RosType[Any]) -> Any:
    def decode(msg: Any) -> Any:
        if isinstance(msg, bytes | msgspec.Raw):
            return codec.decode(msg)
        return codec.convert(msg)

    return decode


DECODERS = {name: _decoder(codec) for name, codec in ROS_TYPES.items()}
decode_pose = _decoder(POSE)
decode_int32 = _decoder(INT32)
decode_string = _decoder(STRING)
decode_diagnostics = _decoder(DIAGNOSTICS)
decode_person_detections = _decoder(PERSONS)
decode_face_data = _decoder(FACES)
decode_tracked_people = _decoder(PEOPLE)
decode_clock = _decoder(CLOCK)
encode_int32 = INT32.encode
encode_string = STRING.encode
encode_clock = CLOCK.encode


def encode_pose(
    x: float, y: float, qz: float, qw: float, stamp: float, frame: str = "map"
) -> dict[str, Any]:
    return POSE.encode(Pose(stamp, frame, x, y, qz, qw))
