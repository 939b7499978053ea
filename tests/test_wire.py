"""The wire table is the one place an input is declared.

A made-up input (a lidar that says whether the corridor ahead is clear, and how wide it
is) of a made-up ROS type is registered in :data:`frog_bt.model.wire.INPUTS` alone, with its
type in :data:`frog_bt.model.ros.ROS_TYPES` and a leaf that reads its key; nothing
else is touched. It is then subscribed to by the executive, decoded from rosbridge's
JSON, snapshotted onto the blackboard for the leaf, given a JSON schema in recordings
and encoded by the simulator's codec.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import ClassVar

import msgspec
import pytest
from bench import Bench, write_tree
from links import FakeFrontend, FakeRobot

from frog_bt.behaviours import FACTORY, load_tree
from frog_bt.clock import WallClock
from frog_bt.codec import Finite
from frog_bt.config import load_site
from frog_bt.errors import DecodeError
from frog_bt.model.channels import schema_for
from frog_bt.model.key import Reading
from frog_bt.model.ros import ROS_TYPES, RosType
from frog_bt.model.wire import INPUTS, Input, input_key
from frog_bt.runtime.executive import Executive
from frog_bt.tree.leaf import RUNNING, SUCCESS, Leaf, Status


class Corridor(msgspec.Struct, frozen=True):
    """The made-up message (in frog_bt/model/ros.py it would sit beside the others)."""

    ros_type: ClassVar[str] = "frog_msgs/Corridor"
    clear: bool
    width: Finite  # metres

    def value(self) -> tuple[bool, float]:
        return self.clear, self.width

    @classmethod
    def of(cls, value: tuple[bool, float]) -> Corridor:
        return cls(*value)


CORRIDOR_TYPE: RosType[tuple[bool, float]] = RosType(Corridor)
# In frog_bt/model/wire.py, beside its topic: the input's key (its type is the value's Reading)
CORRIDOR = input_key(
    "/corridor", Reading[tuple[bool, float]], "whether the corridor ahead is clear, and its width"
)


class CorridorClear(Leaf):
    """Reads ``/corridor``: SUCCESS once the lidar says clear, else RUNNING."""

    reads = (CORRIDOR,)

    def update(self) -> Status:
        reading = self.get(CORRIDOR)
        return SUCCESS if reading is not None and reading.value[0] else RUNNING


@pytest.fixture
def corridor(monkeypatch: pytest.MonkeyPatch) -> Iterator[Input]:
    entry = Input("/lidar/corridor", CORRIDOR_TYPE, CORRIDOR)  # the one table entry
    monkeypatch.setitem(ROS_TYPES, CORRIDOR_TYPE.name, CORRIDOR_TYPE)  # its new type
    monkeypatch.setitem(INPUTS, "corridor", entry)
    monkeypatch.setitem(FACTORY.leaves, "CorridorClear", CorridorClear)  # and its leaf
    yield entry


def test_a_new_input_reaches_its_leaf_through_the_table_alone(
    corridor: Input, tmp_path: Path
) -> None:
    bench = Bench(write_tree(tmp_path, "root: {type: CorridorClear}"))
    assert bench.tick() == RUNNING
    value = corridor.codec.decode(b'{"clear": false, "width": 0.4}')  # as rosbridge sends it
    assert value == (False, 0.4)
    assert bench.core.on_ros("/lidar/corridor", value)  # it calls for a tick
    assert bench.tick() == RUNNING
    bench.core.on_ros("/lidar/corridor", corridor.codec.decode(b'{"clear": true, "width": 2}'))
    assert bench.tick() == SUCCESS
    with pytest.raises(DecodeError, match="width"):
        corridor.codec.decode(b'{"clear": true, "width": "wide"}')


def test_a_new_input_is_subscribed_recorded_and_simulated(corridor: Input, tmp_path: Path) -> None:
    site = load_site()
    tree = load_tree(write_tree(tmp_path, "root: {type: CorridorClear}"), site)
    robot = FakeRobot()
    executive = Executive(site, tree, WallClock(), robot, FakeFrontend())
    executive.setup_wire()
    assert robot.subscribed["/lidar/corridor"] == "frog_msgs/Corridor"
    schema = schema_for(corridor.type)
    assert schema["title"] == "frog_msgs/Corridor"
    assert schema["properties"]["clear"] == {"type": "boolean"}
    assert schema["properties"]["width"]["type"] == "number"
    assert schema["required"] == ["clear", "width"]
    assert corridor.codec.encode((True, 1.5)) == {"clear": True, "width": 1.5}
    assert corridor.codec.decode(b'{"clear": true, "width": 1.5}') == (True, 1.5)


def test_a_leaf_reading_a_key_no_input_writes_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(FACTORY.leaves, "CorridorClear", CorridorClear)
    with pytest.raises(Exception, match="uses /corridor, which no key declaration knows"):
        load_tree(write_tree(tmp_path, "root: {type: CorridorClear}"), load_site())
