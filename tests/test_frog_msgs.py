"""The ROS package ``ros/frog_msgs`` against the contract, the simulator and the decoders.

The ``.msg`` files are the source of truth for the perception messages. This
test parses them (a tiny parser: ``type name`` lines, comments stripped, ``T[]``
arrays) and checks, field by field, that

* they are CONTRACT's definitions, comments included;
* the simulator's JSON (:mod:`frog_bt.sim.msgs`) has every field, no other
  field, and JSON types matching the ROS types;
* the executive's decoders (:mod:`frog_bt.model.ros`) accept a message built from
  the definition and read every field;
* ``package.xml`` and ``CMakeLists.txt`` build the package with catkin.
"""

from __future__ import annotations

import copy
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import rosmsgs

from frog_bt.errors import DecodeError
from frog_bt.model import ros as messages

PACKAGE = Path(__file__).resolve().parents[1] / "ros" / "frog_msgs"
MSG_DIR = PACKAGE / "msg"

# CONTRACT.md, "FROG message definitions", verbatim.
CONTRACT_DEFINITIONS = """\
# frog_msgs/PersonDetections
std_msgs/Header header
frog_msgs/PersonDetection[] persons
# frog_msgs/PersonDetection
int32 id
geometry_msgs/Point position     # map frame
float32 orientation              # degrees 0..360 relative to the robot, 180 = facing it

# frog_msgs/FaceData
std_msgs/Header header
frog_msgs/Face[] faces
# frog_msgs/Face
int32 id
float32 engagement               # -1 .. 1
float32 distance                 # metres
bool facing

# frog_msgs/TrackedPeople
std_msgs/Header header
frog_msgs/TrackedPerson[] people
# frog_msgs/TrackedPerson
int32 id
geometry_msgs/Point position     # map frame
"""

# Top-level message -> the executive's decoder for it.
TOP_LEVEL = {
    "PersonDetections": rosmsgs.decode_person_detections,
    "FaceData": rosmsgs.decode_face_data,
    "TrackedPeople": rosmsgs.decode_tracked_people,
}


# ------------------------------------------------------------------ the parser


@dataclass(frozen=True, slots=True)
class Field:
    type: str  # as written, without "[]": "int32", "geometry_msgs/Point", "frog_msgs/Face"
    name: str
    array: bool


def parse_msg(text: str) -> list[Field]:
    """Fields of a ``.msg`` text; constants and bounded arrays are not used by FROG."""
    fields = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = re.fullmatch(r"([A-Za-z_][\w/]*)(\[\])?\s+([a-z_]\w*)", line)
        assert match, f"cannot parse .msg line {raw!r}"
        fields.append(Field(match[1], match[3], match[2] is not None))
    return fields


def contract_blocks() -> dict[str, str]:
    """CONTRACT's definitions split per message: name -> text of its ``.msg`` file."""
    blocks: dict[str, list[str]] = {}
    current: list[str] = []
    for line in CONTRACT_DEFINITIONS.splitlines():
        if line.startswith("# frog_msgs/"):
            current = blocks.setdefault(line.removeprefix("# frog_msgs/"), [])
        if line:
            current.append(line)
    return {name: "\n".join(lines) + "\n" for name, lines in blocks.items()}


def load_definitions() -> dict[str, list[Field]]:
    return {path.stem: parse_msg(path.read_text()) for path in sorted(MSG_DIR.glob("*.msg"))}


DEFS = load_definitions()


def own_name(type_: str) -> str | None:
    """``frog_msgs/Face`` or ``Face`` -> ``Face``; None for other packages and builtins."""
    if type_.startswith("frog_msgs/"):
        return type_.removeprefix("frog_msgs/")
    return type_ if type_ in DEFS else None


def test_parser() -> None:
    fields = parse_msg("# head\n\nint32 id  # comment\nfoo_msgs/Bar[] bars\n")
    assert fields == [Field("int32", "id", False), Field("foo_msgs/Bar", "bars", True)]


# ------------------------------------------------------------------ the files


def test_msg_files_are_the_contract_definitions() -> None:
    expected = contract_blocks()
    assert set(expected) == {
        "PersonDetections",
        "PersonDetection",
        "FaceData",
        "Face",
        "TrackedPeople",
        "TrackedPerson",
    }
    assert {p.name for p in MSG_DIR.iterdir()} == {f"{name}.msg" for name in expected}
    for name, text in expected.items():
        assert (MSG_DIR / f"{name}.msg").read_text() == text, name


def test_every_referenced_type_is_known() -> None:
    builtins = {"int32", "float32", "bool", "string"}
    external = {"std_msgs/Header", "geometry_msgs/Point"}
    for name, fields in DEFS.items():
        for f in fields:
            assert f.type in builtins | external or own_name(f.type) in DEFS, (name, f)


def test_package_xml() -> None:
    root = ET.parse(PACKAGE / "package.xml").getroot()
    assert root.tag == "package" and root.get("format") == "2"
    assert root.findtext("name") == "frog_msgs"
    for tag in ("version", "description", "license"):
        assert (root.findtext(tag) or "").strip(), tag
    maintainer = root.find("maintainer")
    assert maintainer is not None and maintainer.get("email")

    def deps(*tags: str) -> set[str]:
        return {(e.text or "").strip() for tag in tags for e in root.findall(tag)}

    assert deps("buildtool_depend") == {"catkin"}
    assert "message_generation" in deps("build_depend")
    assert "message_runtime" in deps("exec_depend", "depend")
    used = {f.type.split("/")[0] for fs in DEFS.values() for f in fs if "/" in f.type}
    assert used - {"frog_msgs"} == {"std_msgs", "geometry_msgs"}
    for pkg in used - {"frog_msgs"}:
        assert pkg in deps("depend", "build_depend"), pkg
        assert pkg in deps("depend", "exec_depend"), pkg


def cmake_call(text: str, command: str) -> list[str]:
    match = re.search(rf"^\s*{command}\s*\(([^)]*)\)", text, re.MULTILINE | re.IGNORECASE)
    assert match, f"CMakeLists.txt has no {command}()"
    return match[1].split()


def test_cmakelists() -> None:
    text = (PACKAGE / "CMakeLists.txt").read_text()
    text = re.sub(r"#.*", "", text)
    assert cmake_call(text, "project") == ["frog_msgs"]
    find = cmake_call(text, "find_package")
    assert find[:2] == ["catkin", "REQUIRED"]
    assert {"message_generation", "std_msgs", "geometry_msgs"} <= set(find)
    files = cmake_call(text, "add_message_files")
    assert files[0] == "FILES"
    assert sorted(files[1:]) == sorted(p.name for p in MSG_DIR.glob("*.msg"))
    gen = cmake_call(text, "generate_messages")
    assert gen[0] == "DEPENDENCIES" and set(gen[1:]) == {"std_msgs", "geometry_msgs"}
    pkg = cmake_call(text, "catkin_package")
    assert pkg[0] == "CATKIN_DEPENDS" and "message_runtime" in pkg
    # generate_messages() must come after add_message_files(), catkin_package() after both.
    order = [text.index(c) for c in ("add_message_files", "generate_messages", "catkin_package")]
    assert order == sorted(order)


def test_wire_structs_have_the_msg_fields() -> None:
    """Each frog_msgs type has a codec whose wire Struct has exactly the .msg's fields."""
    wires = {
        "Face": messages.Face,
        "PersonDetection": messages.PersonDetection,
        "TrackedPerson": messages.TrackedPerson,
    }
    for name in TOP_LEVEL:
        codec = messages.ROS_TYPES[f"frog_msgs/{name}"]
        assert codec.name == f"frog_msgs/{name}"
        wires[name] = codec.wire
    for name, wire in wires.items():
        assert set(wire.__struct_fields__) == {f.name for f in DEFS[name]}, name


# ------------------------------------------------------------------ JSON schema check


def is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | float) and math.isfinite(value)


def check_json(value: Any, type_: str, path: str = "msg") -> None:
    """Assert ``value`` is the rosbridge JSON of one ROS ``type_`` value."""
    if type_ == "int32":
        assert isinstance(value, int) and not isinstance(value, bool), f"{path}: {value!r}"
        assert -(2**31) <= value < 2**31, path
    elif type_ in ("float32", "float64"):
        assert is_number(value), f"{path}: expected a number, got {value!r}"
    elif type_ == "bool":
        assert isinstance(value, bool), f"{path}: expected a bool, got {value!r}"
    elif type_ == "string":
        assert isinstance(value, str), f"{path}: expected a string, got {value!r}"
    elif type_ == "geometry_msgs/Point":
        assert isinstance(value, dict) and set(value) == {"x", "y", "z"}, f"{path}: {value!r}"
        for axis in "xyz":
            check_json(value[axis], "float64", f"{path}.{axis}")
    elif type_ == "std_msgs/Header":
        assert isinstance(value, dict), path
        assert {"stamp", "frame_id"} <= set(value) <= {"seq", "stamp", "frame_id"}, path
        if "seq" in value:
            assert isinstance(value["seq"], int) and not isinstance(value["seq"], bool)
            assert 0 <= value["seq"] < 2**32, f"{path}.seq"
        stamp = value["stamp"]
        assert isinstance(stamp, dict) and set(stamp) == {"secs", "nsecs"}, f"{path}.stamp"
        for key in ("secs", "nsecs"):
            assert isinstance(stamp[key], int) and not isinstance(stamp[key], bool), key
        assert 0 <= stamp["nsecs"] < 1_000_000_000, f"{path}.stamp.nsecs"
        assert isinstance(value["frame_id"], str), f"{path}.frame_id"
    else:
        name = own_name(type_)
        assert name is not None, f"{path}: no definition for {type_}"
        fields = DEFS[name]
        assert isinstance(value, dict), f"{path}: expected an object, got {value!r}"
        assert set(value) == {f.name for f in fields}, (
            f"{path}: fields {sorted(value)} != {name}.msg {[f.name for f in fields]}"
        )
        for f in fields:
            if f.array:
                assert isinstance(value[f.name], list), f"{path}.{f.name}"
                for i, item in enumerate(value[f.name]):
                    check_json(item, f.type, f"{path}.{f.name}[{i}]")
            else:
                check_json(value[f.name], f.type, f"{path}.{f.name}")


def test_check_json_rejects_what_it_should() -> None:
    good = {"id": 1, "engagement": 0.5, "distance": 1.0, "facing": True}
    check_json(good, "frog_msgs/Face")
    for bad in (
        {**good, "id": True},
        {**good, "facing": 1},
        {**good, "distance": "1"},
        {**good, "extra": 0},
        {k: v for k, v in good.items() if k != "id"},
        {**good, "engagement": float("nan")},
    ):
        with pytest.raises(AssertionError):
            check_json(bad, "frog_msgs/Face")


# ------------------------------------------------------------------ simulator


P = messages.Point
STAMP = 1_700_000_123.25
# Top-level message -> its builder in frog_bt.sim.msgs.
BUILDERS = {
    "PersonDetections": "person_detections",
    "FaceData": "face_data",
    "TrackedPeople": "tracked_people",
}


@pytest.fixture(scope="module")
def sim() -> Any:
    return pytest.importorskip(
        "frog_bt.sim.msgs", reason="the simulator's frog_bt.sim.msgs is not importable"
    )


def sim_cases() -> Iterator[tuple[str, list[Any], bool]]:
    """(message, items, items are dataclasses)."""
    yield (
        "PersonDetections",
        [
            messages.PersonDetection(7, P(1.5, -2.0, 0.25), 181.0),
            messages.PersonDetection(8, P(3.0, 4.0, 0.0), 0.0),
        ],
        True,
    )
    yield (
        "PersonDetections",
        [
            {"id": 9, "position": {"x": 1, "y": 2, "z": 0}, "orientation": 90},
        ],
        False,
    )
    yield (
        "FaceData",
        [
            messages.Face(7, 0.4, 1.2, True),
            messages.Face(2, -1.0, 0.0, False),
        ],
        True,
    )
    yield (
        "FaceData",
        [
            {"id": 3, "engagement": 1, "distance": 2, "facing": True},
        ],
        False,
    )
    yield (
        "TrackedPeople",
        [
            messages.TrackedPerson(3, P(55.7, 85.4, 0.0)),
            messages.TrackedPerson(4, P(0.0, 0.0)),
        ],
        True,
    )
    yield (
        "TrackedPeople",
        [
            {"id": 5, "position": {"x": 1.0, "y": 2.0, "z": 3.0}},
        ],
        False,
    )


SIM_CASES = list(sim_cases())


@pytest.mark.parametrize(
    ("name", "items", "typed"),
    SIM_CASES,
    ids=[f"{c[0]}-{'dataclass' if c[2] else 'mapping'}" for c in SIM_CASES],
)
def test_simulator_json_matches_msg(sim: Any, name: str, items: list[Any], typed: bool) -> None:
    build: Callable[..., dict] = getattr(sim, BUILDERS[name])
    msg = build(STAMP, items)
    check_json(msg, f"frog_msgs/{name}")
    array = next(f.name for f in DEFS[name] if f.array)
    assert len(msg[array]) == len(items)
    decoded = TOP_LEVEL[name](msg)
    assert decoded.stamp == pytest.approx(STAMP)
    if typed:
        assert list(getattr(decoded, array)) == items


@pytest.mark.parametrize("name", list(TOP_LEVEL))
def test_simulator_json_with_no_items(sim: Any, name: str) -> None:
    msg = getattr(sim, BUILDERS[name])(STAMP, [])
    check_json(msg, f"frog_msgs/{name}")
    assert TOP_LEVEL[name](msg).stamp == pytest.approx(STAMP)


# ------------------------------------------------------------------ decoders

HEADER_SAMPLE = {
    "seq": 3,
    "stamp": {"secs": 1_700_000_000, "nsecs": 500_000_000},
    "frame_id": "map",
}


class Samples:
    """Distinct, valid sample values for every field type (floats stay in [0, 1))."""

    def __init__(self) -> None:
        self.n = 0

    def next(self) -> int:
        self.n += 1
        return self.n

    def value(self, type_: str) -> Any:
        if type_ == "int32":
            return 100 + self.next()
        if type_ == "float32":
            return (self.next() % 8) / 8 + 1 / 16  # in range for degrees, engagement, metres
        if type_ == "bool":
            return True
        if type_ == "string":
            return f"s{self.next()}"
        if type_ == "geometry_msgs/Point":
            return {axis: self.next() + 0.5 for axis in "xyz"}
        if type_ == "std_msgs/Header":
            return copy.deepcopy(HEADER_SAMPLE)
        name = own_name(type_)
        assert name is not None, type_
        return {
            f.name: [self.value(f.type) for _ in range(2)] if f.array else self.value(f.type)
            for f in DEFS[name]
        }


def assert_read(decoded: Any, value: Any, type_: str, path: str) -> None:
    """Every field of the JSON ``value`` shows up in the decoded dataclass."""
    if type_ == "std_msgs/Header":
        stamp = value["stamp"]
        assert decoded == pytest.approx(stamp["secs"] + stamp["nsecs"] * 1e-9), path
    elif type_ == "geometry_msgs/Point":
        assert (decoded.x, decoded.y, decoded.z) == (value["x"], value["y"], value["z"]), path
    elif own_name(type_) is not None:
        for f in DEFS[own_name(type_) or ""]:
            attr = "stamp" if f.type == "std_msgs/Header" else f.name
            assert hasattr(decoded, attr), f"{path}: decoder drops {f.name}"
            got = getattr(decoded, attr)
            if f.array:
                assert len(got) == len(value[f.name]), f"{path}.{f.name}"
                for i, (g, v) in enumerate(zip(got, value[f.name], strict=True)):
                    assert_read(g, v, f.type, f"{path}.{f.name}[{i}]")
            else:
                assert_read(got, value[f.name], f.type, f"{path}.{f.name}")
    else:
        assert got_equal(decoded, value), f"{path}: {decoded!r} != {value!r}"


def got_equal(decoded: Any, value: Any) -> bool:
    return (type(decoded) is type(value) and decoded == value) or (
        isinstance(value, float) and decoded == pytest.approx(value)
    )


def leaf_paths(value: Any, prefix: tuple[str | int, ...] = ()) -> Iterator[tuple[str | int, ...]]:
    if isinstance(value, dict):
        for key, item in value.items():
            yield from leaf_paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from leaf_paths(item, (*prefix, i))
    else:
        yield prefix


def replaced(msg: dict, path: tuple[str | int, ...], new: Any) -> dict:
    out = copy.deepcopy(msg)
    target: Any = out
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = new
    return out


def removed(msg: dict, path: tuple[str | int, ...]) -> dict:
    out = copy.deepcopy(msg)
    target: Any = out
    for key in path[:-1]:
        target = target[key]
    del target[path[-1]]
    return out


@pytest.mark.parametrize("name", list(TOP_LEVEL))
def test_decoder_reads_every_field(name: str) -> None:
    msg = Samples().value(f"frog_msgs/{name}")
    check_json(msg, f"frog_msgs/{name}")
    assert_read(TOP_LEVEL[name](msg), msg, f"frog_msgs/{name}", name)


@pytest.mark.parametrize("name", list(TOP_LEVEL))
def test_decoder_checks_every_field(name: str) -> None:
    """A wrong type at any leaf (but the unused ``header.seq``) is a DecodeError naming it."""
    decode = TOP_LEVEL[name]
    msg = Samples().value(f"frog_msgs/{name}")
    paths = [p for p in leaf_paths(msg) if p != ("header", "seq")]
    assert len(paths) > 5
    for path in paths:
        current: Any = msg
        for key in path:
            current = current[key]
        wrong = 5 if isinstance(current, str) else "wrong"
        with pytest.raises(DecodeError) as info:
            decode(replaced(msg, path, wrong))
        assert info.value.path[:1] == path[:1], path


@pytest.mark.parametrize("name", list(TOP_LEVEL))
def test_decoder_requires_every_element_field(name: str) -> None:
    """Each field of an array element is required (a Point's ``z`` defaults to 0)."""
    decode = TOP_LEVEL[name]
    msg = Samples().value(f"frog_msgs/{name}")
    array = next(f for f in DEFS[name] if f.array)
    element = DEFS[own_name(array.type) or ""]
    for f in element:
        path = (array.name, 1, f.name)
        with pytest.raises(DecodeError) as info:
            decode(removed(msg, path))
        assert info.value.path == path
        if f.type == "geometry_msgs/Point":
            for axis in "xy":
                with pytest.raises(DecodeError):
                    decode(removed(msg, (*path, axis)))
    with pytest.raises(DecodeError):
        decode(removed(msg, (array.name,)))
