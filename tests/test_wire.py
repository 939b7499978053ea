"""The wire table is the one place an input is declared.

A made-up input (a lidar that says whether the corridor ahead is clear) is
registered in :data:`frog_bt.wire.INPUTS` alone, with a leaf that reads its key;
nothing else is touched. It is then subscribed to by the executive, decoded
from rosbridge's JSON, snapshotted onto the blackboard for the leaf, given a
JSON schema in recordings and encoded by the simulator's codec.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from bench import Bench, write_tree

from frog_bt.config import load_site
from frog_bt.kernel.clock import WallClock
from frog_bt.kernel.key import Reading
from frog_bt.observers.recording import SCHEMAS
from frog_bt.rosbridge import msgs
from frog_bt.runtime.executive import Executive
from frog_bt.tree.leaf import LEAVES, RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.loader import load_tree
from frog_bt.wire import INPUTS, Input, input_key

# In frog_bt/wire.py, beside its topic: the input's key (its type is the value's Reading)
CORRIDOR = input_key("/corridor", Reading[str], "whether the corridor ahead is clear")


class CorridorClear(Leaf):
    """Reads ``/corridor``: SUCCESS once the lidar says ``clear``, else RUNNING."""

    reads = (CORRIDOR,)

    def update(self) -> Status:
        reading = self.get(CORRIDOR)
        return SUCCESS if reading is not None and reading.value == "clear" else RUNNING


@pytest.fixture
def corridor(monkeypatch: pytest.MonkeyPatch) -> Iterator[Input]:
    entry = Input("/lidar/corridor", msgs.STRING, CORRIDOR)  # the one table entry
    monkeypatch.setitem(INPUTS, "corridor", entry)
    monkeypatch.setitem(LEAVES, "CorridorClear", CorridorClear)  # and its leaf
    yield entry


def test_a_new_input_reaches_its_leaf_through_the_table_alone(corridor: Input,
                                                              tmp_path: Path) -> None:
    bench = Bench(write_tree(tmp_path, "root: {type: CorridorClear}"))
    assert bench.tick() == RUNNING
    value = corridor.codec.decode(b'{"data": "blocked"}')  # as rosbridge sends it
    assert bench.core.on_ros("/lidar/corridor", value)  # it calls for a tick
    assert bench.tick() == RUNNING
    bench.core.on_ros("/lidar/corridor", corridor.codec.decode(b'{"data": "clear"}'))
    assert bench.tick() == SUCCESS


def test_a_new_input_is_subscribed_recorded_and_simulated(corridor: Input,
                                                          tmp_path: Path) -> None:
    site = load_site()
    tree = load_tree(write_tree(tmp_path, "root: {type: CorridorClear}"), site)
    executive = Executive(site, tree, WallClock(), rosbridge_url="ws://127.0.0.1:9",
                          frontend=("127.0.0.1", 9), listen=("127.0.0.1", 0))
    executive.setup_wire()
    assert executive.client.session.subscriptions["/lidar/corridor"].type == "std_msgs/String"
    assert SCHEMAS[corridor.type]["properties"]["data"] == {"type": "string"}
    assert corridor.codec.encode("clear") == {"data": "clear"}


def test_a_leaf_reading_a_key_no_input_writes_is_refused(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    monkeypatch.setitem(LEAVES, "CorridorClear", CorridorClear)
    with pytest.raises(Exception, match="uses /corridor, which no key declaration knows"):
        load_tree(write_tree(tmp_path, "root: {type: CorridorClear}"), load_site())
