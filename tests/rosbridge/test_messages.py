"""ROS message decoders and encoders (CONTRACT §1): valid examples, every error path,
and a hypothesis property per decoder: any JSON-like value decodes or raises DecodeError."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosmsgs import (
    DECODERS,
    decode_clock,
    decode_diagnostics,
    decode_face_data,
    decode_int32,
    decode_person_detections,
    decode_pose,
    decode_string,
    decode_tracked_people,
    encode_clock,
    encode_int32,
    encode_pose,
    encode_string,
)

from frog_bt.codec import convert
from frog_bt.errors import DecodeError, format_path
from frog_bt.model.ros import (
    ROS_TYPES,
    Diagnostics,
    Face,
    FaceData,
    PersonDetection,
    PersonDetections,
    Point,
    Pose,
    Time,
    TrackedPeople,
    TrackedPerson,
    encode_time,
)

ROS1_HEADER = {"seq": 4, "stamp": {"secs": 1_700_000_000, "nsecs": 500_000_000}, "frame_id": "map"}
ROS2_HEADER = {"stamp": {"sec": 1_700_000_000, "nanosec": 500_000_000}, "frame_id": "map"}
STAMP = 1_700_000_000.5


def pose_msg(header: dict[str, Any] = ROS1_HEADER) -> dict[str, Any]:
    return {
        "header": header,
        "pose": {
            "position": {"x": 97.19, "y": 63.02, "z": 0.0},
            "orientation": {"x": 0.0, "y": 0.0, "z": 0.898316, "w": 0.43934},
        },
    }


def diagnostics_msg(header: dict[str, Any] = ROS1_HEADER) -> dict[str, Any]:
    return {
        "header": header,
        "status": [
            {
                "level": 0,
                "name": "battery",
                "message": "",
                "hardware_id": "",
                "values": [
                    {"key": "voltage", "value": "24.1"},
                    {"key": "percentage", "value": "73.5"},
                ],
            },
            {
                "level": 2,
                "name": "motors",
                "message": "overcurrent",
                "hardware_id": "m1",
                "values": [],
            },
            {"level": 3, "name": "lidar", "message": "", "hardware_id": "", "values": []},
            {"level": 1, "name": "fan", "message": "slow", "hardware_id": "", "values": []},
        ],
    }


def persons_msg(header: dict[str, Any] = ROS1_HEADER) -> dict[str, Any]:
    return {
        "header": header,
        "persons": [{"id": 7, "position": {"x": 1.0, "y": 2.0, "z": 0.0}, "orientation": 181.0}],
    }


def faces_msg(header: dict[str, Any] = ROS1_HEADER) -> dict[str, Any]:
    return {
        "header": header,
        "faces": [
            {"id": 7, "engagement": 0.4, "distance": 1.2, "facing": True},
            {"id": 8, "engagement": -1, "distance": 0, "facing": False},
        ],
    }


def people_msg(header: dict[str, Any] = ROS1_HEADER) -> dict[str, Any]:
    return {"header": header, "people": [{"id": 3, "position": {"x": 5, "y": 6.5, "z": 0.0}}]}


# type -> (valid example, the type of the decoded value)
EXAMPLES: dict[str, tuple[Callable[..., Any], type]] = {
    "geometry_msgs/PoseStamped": (pose_msg, Pose),
    "std_msgs/Int32": (lambda header=None: {"data": 2}, int),
    "std_msgs/String": (lambda header=None: {"data": "docked"}, str),
    "diagnostic_msgs/DiagnosticArray": (diagnostics_msg, Diagnostics),
    "frog_msgs/PersonDetections": (persons_msg, PersonDetections),
    "frog_msgs/FaceData": (faces_msg, FaceData),
    "frog_msgs/TrackedPeople": (people_msg, TrackedPeople),
    "rosgraph_msgs/Clock": (lambda header=None: {"clock": {"secs": 12, "nsecs": 5}}, float),
}


def test_every_decoder_has_an_example() -> None:
    assert set(EXAMPLES) == set(DECODERS)


def decode_error(decoder: Callable[[Any], Any], msg: Any) -> DecodeError:
    with pytest.raises(DecodeError) as info:
        decoder(msg)
    return info.value


# ---------------------------------------------------------------- valid examples


@pytest.mark.parametrize("header", [ROS1_HEADER, ROS2_HEADER], ids=["ros1", "ros2"])
def test_pose(header: dict[str, Any]) -> None:
    pose = decode_pose(pose_msg(header))
    assert pose == Pose(STAMP, "map", 97.19, 63.02, 0.898316, 0.43934)
    assert pose.yaw == pytest.approx(2 * math.atan2(0.898316, 0.43934))


def test_pose_without_header_or_orientation_z() -> None:
    msg = {"pose": {"position": {"x": 1, "y": 2}, "orientation": {"w": 1}}}
    assert decode_pose(msg) == Pose(0.0, "", 1.0, 2.0, 0.0, 1.0)


def test_int32_and_string() -> None:
    assert decode_int32({"data": 4}) == 4
    assert decode_int32({"data": -(2**31)}) == -(2**31)
    assert decode_string({"data": "undocking"}) == "undocking"
    assert decode_string({"data": ""}) == ""


@pytest.mark.parametrize("header", [ROS1_HEADER, ROS2_HEADER], ids=["ros1", "ros2"])
def test_diagnostics(header: dict[str, Any]) -> None:
    assert decode_diagnostics(diagnostics_msg(header)) == Diagnostics(
        STAMP, 73.5, ("motors: overcurrent", "lidar")
    )


def test_diagnostics_without_battery_or_values() -> None:
    msg = {"status": [{"level": 0, "name": "cpu"}]}
    assert decode_diagnostics(msg) == Diagnostics(0.0, None, ())
    assert decode_diagnostics({"status": []}) == Diagnostics(0.0, None, ())


@pytest.mark.parametrize("header", [ROS1_HEADER, ROS2_HEADER], ids=["ros1", "ros2"])
def test_person_detections(header: dict[str, Any]) -> None:
    assert decode_person_detections(persons_msg(header)) == PersonDetections(
        STAMP, (PersonDetection(7, Point(1.0, 2.0, 0.0), 181.0),)
    )


@pytest.mark.parametrize("header", [ROS1_HEADER, ROS2_HEADER], ids=["ros1", "ros2"])
def test_face_data(header: dict[str, Any]) -> None:
    assert decode_face_data(faces_msg(header)) == FaceData(
        STAMP, (Face(7, 0.4, 1.2, True), Face(8, -1.0, 0.0, False))
    )


@pytest.mark.parametrize("header", [ROS1_HEADER, ROS2_HEADER], ids=["ros1", "ros2"])
def test_tracked_people(header: dict[str, Any]) -> None:
    assert decode_tracked_people(people_msg(header)) == TrackedPeople(
        STAMP, (TrackedPerson(3, Point(5.0, 6.5, 0.0)),)
    )


def test_clock_both_time_shapes() -> None:
    assert decode_clock({"clock": {"secs": 12, "nsecs": 5}}) == pytest.approx(12.000000005)
    assert decode_clock({"clock": {"sec": 12, "nanosec": 5}}) == pytest.approx(12.000000005)


def test_encoders_decode_back() -> None:
    assert decode_pose(encode_pose(97.19, 63.02, -0.56311, 0.82638, STAMP)) == Pose(
        STAMP, "map", 97.19, 63.02, -0.56311, 0.82638
    )
    assert encode_pose(1, 2, 0, 1, STAMP)["header"]["stamp"] == {
        "secs": 1_700_000_000,
        "nsecs": 500_000_000,
    }  # ROS 1 shape on the way out
    assert decode_int32(encode_int32(17)) == 17
    assert decode_string(encode_string("dock")) == "dock"
    assert decode_clock(encode_clock(STAMP)) == STAMP


# ---------------------------------------------------------------- error paths


@pytest.mark.parametrize(
    ("decoder", "msg", "path"),
    [
        # not an object at all
        (decode_pose, [], ()),
        (decode_int32, None, ()),
        (decode_string, "docked", ()),
        # missing fields
        (decode_int32, {}, ("data",)),
        (decode_pose, {"header": ROS1_HEADER}, ("pose",)),
        (
            decode_pose,
            {"pose": {"position": {"x": 1}, "orientation": {"w": 1}}},
            ("pose", "position", "y"),
        ),
        (
            decode_pose,
            {"pose": {"position": {"x": 1, "y": 2}, "orientation": {"z": 1}}},
            ("pose", "orientation", "w"),
        ),
        (decode_diagnostics, {"status": [{"level": 0}]}, ("status", 0, "name")),
        (decode_diagnostics, {"header": {}}, ("status",)),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": 0, "distance": 1}]},
            ("faces", 0, "facing"),
        ),
        (
            decode_person_detections,
            {"persons": [{"id": 1, "orientation": 180}]},
            ("persons", 0, "position"),
        ),
        (decode_tracked_people, {"people": [{"position": {"x": 0, "y": 0}}]}, ("people", 0, "id")),
        (decode_clock, {}, ("clock",)),
        (decode_clock, {"clock": {"secs": 1}}, ("clock",)),
        (decode_clock, {"clock": {"sec": 1}}, ("clock",)),
        (decode_clock, {"clock": {"seconds": 1}}, ("clock",)),
        # wrong types
        (decode_int32, {"data": "2"}, ("data",)),
        (decode_int32, {"data": 2.0}, ("data",)),
        (decode_string, {"data": 3}, ("data",)),
        (
            decode_pose,
            {"pose": {"position": {"x": "1", "y": 2}, "orientation": {"w": 1}}},
            ("pose", "position", "x"),
        ),
        (decode_pose, {"header": [], "pose": {}}, ("header",)),
        (decode_pose, dict(pose_msg(), header={"frame_id": 5}), ("header", "frame_id")),
        (decode_pose, dict(pose_msg(), header={"stamp": 5}), ("header", "stamp")),
        (decode_diagnostics, {"status": {}}, ("status",)),
        (decode_diagnostics, {"status": ["ok"]}, ("status", 0)),
        (decode_diagnostics, {"status": [{"level": "2", "name": "x"}]}, ("status", 0, "level")),
        (
            decode_diagnostics,
            {"status": [{"level": 0, "name": "x", "values": [{"key": "k"}]}]},
            ("status", 0, "values", 0, "value"),
        ),
        (
            decode_diagnostics,
            {
                "status": [
                    {
                        "level": 0,
                        "name": "battery",
                        "values": [{"key": "percentage", "value": 73.5}],
                    }
                ]
            },
            ("status", 0, "values", 0, "value"),
        ),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": 0, "distance": 1, "facing": "yes"}]},
            ("faces", 0, "facing"),
        ),
        (decode_person_detections, {"persons": None}, ("persons",)),
        # bool is not a number, and a number is not a bool
        (decode_int32, {"data": True}, ("data",)),
        (
            decode_pose,
            {"pose": {"position": {"x": False, "y": 2}, "orientation": {"w": 1}}},
            ("pose", "position", "x"),
        ),
        (decode_diagnostics, {"status": [{"level": True, "name": "x"}]}, ("status", 0, "level")),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": 0, "distance": 1, "facing": 1}]},
            ("faces", 0, "facing"),
        ),
        (
            decode_tracked_people,
            {"people": [{"id": True, "position": {"x": 0, "y": 0}}]},
            ("people", 0, "id"),
        ),
        (decode_clock, {"clock": {"secs": True, "nsecs": 0}}, ("clock", "secs")),
        # NaN, infinity and numbers too big for a float or an int32
        (
            decode_pose,
            {"pose": {"position": {"x": math.nan, "y": 2}, "orientation": {"w": 1}}},
            ("pose", "position", "x"),
        ),
        (
            decode_pose,
            {"pose": {"position": {"x": 1, "y": 2}, "orientation": {"w": -math.inf}}},
            ("pose", "orientation", "w"),
        ),
        (
            decode_pose,
            {"pose": {"position": {"x": 10**400, "y": 2}, "orientation": {"w": 1}}},
            ("pose", "position", "x"),
        ),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": math.inf, "distance": 1, "facing": True}]},
            ("faces", 0, "engagement"),
        ),
        (
            decode_diagnostics,
            {
                "status": [
                    {
                        "level": 0,
                        "name": "battery",
                        "values": [{"key": "percentage", "value": "nan"}],
                    }
                ]
            },
            ("status", 0, "values", 0, "value"),
        ),
        (
            decode_diagnostics,
            {
                "status": [
                    {
                        "level": 0,
                        "name": "battery",
                        "values": [{"key": "percentage", "value": "full"}],
                    }
                ]
            },
            ("status", 0, "values", 0, "value"),
        ),
        (decode_int32, {"data": 2**31}, ("data",)),
        (decode_int32, {"data": -(2**31) - 1}, ("data",)),
        (decode_clock, {"clock": {"secs": 10**400, "nsecs": 0}}, ("clock",)),
        (decode_clock, {"clock": {"sec": -(2**40), "nanosec": 0}}, ("clock",)),
        # values outside their range
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": 1.01, "distance": 1, "facing": True}]},
            ("faces", 0, "engagement"),
        ),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": -1.5, "distance": 1, "facing": True}]},
            ("faces", 0, "engagement"),
        ),
        (
            decode_face_data,
            {"faces": [{"id": 1, "engagement": 0, "distance": -0.1, "facing": True}]},
            ("faces", 0, "distance"),
        ),
        (
            decode_person_detections,
            {"persons": [{"id": 1, "position": {"x": 0, "y": 0}, "orientation": 360.5}]},
            ("persons", 0, "orientation"),
        ),
        (decode_diagnostics, {"status": [{"level": 4, "name": "x"}]}, ("status", 0, "level")),
        (decode_clock, {"clock": {"secs": 1, "nsecs": 1_000_000_000}}, ("clock",)),
        (decode_clock, {"clock": {"sec": 1, "nanosec": -1}}, ("clock",)),
    ],
)
def test_decode_errors_name_the_field(
    decoder: Callable[[Any], Any], msg: Any, path: tuple[str | int, ...]
) -> None:
    err = decode_error(decoder, msg)
    assert err.path == path
    if path:
        assert str(err).startswith(format_path(path) + ": ")


def test_engagement_bounds_are_inclusive() -> None:
    for level in (-1, -1.0, 0, 1, 1.0):
        decode_face_data({"faces": [{"id": 1, "engagement": level, "distance": 0, "facing": True}]})


def test_decode_error_message_names_path_and_problem() -> None:
    err = decode_error(
        decode_pose, {"pose": {"position": {"x": "abc", "y": 0}, "orientation": {"w": 1}}}
    )
    assert str(err) == "pose.position.x: expected `float`, got `str`"
    err = decode_error(decode_diagnostics, {"status": [{"level": 0, "name": "x"}, 5]})
    assert str(err) == "status[1]: expected `object`, got `int`"


# ---------------------------------------------------------------- properties

KEYS = sorted(
    {
        "header",
        "stamp",
        "secs",
        "nsecs",
        "sec",
        "nanosec",
        "frame_id",
        "pose",
        "position",
        "orientation",
        "x",
        "y",
        "z",
        "w",
        "data",
        "status",
        "level",
        "name",
        "message",
        "values",
        "key",
        "value",
        "persons",
        "faces",
        "people",
        "id",
        "engagement",
        "distance",
        "facing",
        "clock",
    }
)
scalars = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.sampled_from(
        [2**31, -(2**31) - 1, 2**32, 10**400, -(10**400), 999_999_999, 1_000_000_000, -1, 0, 3, 4]
    )
    | st.floats()
    | st.sampled_from(["percentage", "battery", "73.5", "nan", "inf", "1e999", "-0", " 5 "])
    | st.text(max_size=10)
)
json_like = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.dictionaries(st.sampled_from(KEYS) | st.text(max_size=5), inner, max_size=6)
    ),
    max_leaves=30,
)


# Values at the edges of what a decoder must refuse or accept, drawn often.
NASTY: list[Any] = [
    None,
    True,
    False,
    0,
    -1,
    1.5,
    2**31,
    2**32,
    10**400,
    -(10**400),
    math.nan,
    math.inf,
    -math.inf,
    "",
    "73.5",
    "nan",
    [],
    {},
    [{}],
]


def _paths(value: Any, prefix: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _paths(v, (*prefix, i))


def _replace(value: Any, path: tuple[Any, ...], new: Any, delete: bool) -> Any:
    if not path:
        return new
    copy: Any = dict(value) if isinstance(value, dict) else list(value)
    head, rest = path[0], path[1:]
    if delete and not rest:
        del copy[head]
    else:
        copy[head] = _replace(value[head], rest, new, delete)
    return copy


@st.composite
def mutated(draw: st.DrawFn, example: Any) -> Any:
    """A valid example with one node replaced by anything, or removed."""
    path = draw(st.sampled_from(list(_paths(example))))
    if path and draw(st.integers(0, 3)) == 0:
        return _replace(example, path, None, delete=True)
    return _replace(example, path, draw(st.sampled_from(NASTY) | json_like), delete=False)


def _accepts_or_decode_error(ros_type: str, msg: Any) -> None:
    _, value_type = EXAMPLES[ros_type]
    try:
        value = DECODERS[ros_type](msg)
    except DecodeError:
        return
    assert isinstance(value, value_type)
    if isinstance(value, float):
        assert math.isfinite(value)


@pytest.mark.parametrize("ros_type", sorted(DECODERS))
@settings(max_examples=80, deadline=None)
@given(data=st.data())
def test_decoder_accepts_or_raises_decode_error(ros_type: str, data: st.DataObject) -> None:
    make, _ = EXAMPLES[ros_type]
    header = data.draw(st.sampled_from([ROS1_HEADER, ROS2_HEADER]))
    msg = data.draw(json_like | mutated(make(header=header)) | mutated(make(header=header)))
    _accepts_or_decode_error(ros_type, msg)


@given(st.floats(0, 2**32 - 1))
def test_encode_time_round_trip(t: float) -> None:
    encoded = encode_time(t)
    assert 0 <= encoded.nsecs < 1_000_000_000  # type: ignore[operator]
    assert abs(encoded.seconds - t) <= 0.5e-6 + math.ulp(t)  # to the microsecond


@given(st.integers(0, 2**32 - 1), st.integers(0, 999_999_999), st.booleans())
def test_decode_time_round_trip(secs: int, nsecs: int, ros2: bool) -> None:
    shape = {"sec": secs, "nanosec": nsecs} if ros2 else {"secs": secs, "nsecs": nsecs}
    back = encode_time(convert(shape, Time).seconds)
    error_ns = abs((back.secs - secs) * 1_000_000_000 + back.nsecs - nsecs)  # type: ignore[operator]
    assert error_ns <= 500 + math.ulp(float(secs + 1)) * 1e9 + 1  # to the microsecond


# ---------------------------------------------------------------- JSON text and objects


def _outcome(decode: Callable[[Any], Any], msg: Any) -> tuple[str, Any]:
    try:
        return "value", decode(msg)
    except DecodeError as exc:
        return "error", exc.path


@pytest.mark.parametrize("ros_type", sorted(ROS_TYPES))
@settings(max_examples=120, deadline=None)
@given(data=st.data())
def test_json_text_decodes_as_the_objects_convert(ros_type: str, data: st.DataObject) -> None:
    """Live (raw JSON from rosbridge) and in tests (Python objects) a message gives the same
    value, or an error at the same place."""
    make, _ = EXAMPLES[ros_type]
    header = data.draw(st.sampled_from([ROS1_HEADER, ROS2_HEADER, {"frame_id": "map"}]))
    msg = data.draw(mutated(make(header=header)) | json_like)
    if data.draw(st.booleans()):
        msg = data.draw(mutated(msg))  # a second change
    try:
        text = json.dumps(msg, allow_nan=False)
    except ValueError:
        return  # NaN or infinity: not JSON, rosbridge cannot send it
    codec = ROS_TYPES[ros_type]
    assert _outcome(codec.decode, text) == _outcome(codec.convert, msg)


def test_encode_time_at_the_end_of_uint32_does_not_overflow() -> None:
    back = encode_time(Time(secs=2**32 - 1, nsecs=999_999_999).seconds)
    assert (back.secs, back.nsecs) == (2**32 - 1, 999_999_999)
