"""No input stops the executive: a node's own bug is caught at the node, logged once,
recorded and counted; its tick counts as its failure and the tree goes on."""

from __future__ import annotations

import logging
from typing import ClassVar

import pytest
from bench import Bench, write_tree

from frog_bt.config import AlertsCfg
from frog_bt.engine.faults import REPEATED
from frog_bt.model.events import Faulted, Ticked
from frog_bt.runtime.alerts import Facts, conditions
from frog_bt.runtime.observer import listen
from frog_bt.tree.factory import NodeFactory
from frog_bt.tree.leaf import FAILURE, SUCCESS, Leaf, Status


class Buggy(Leaf):
    """Raises in update (a bug a robot's input can reach), or in terminate."""

    where: ClassVar[str] = "update"

    def update(self) -> Status:
        if self.where == "update":
            raise ValueError("datagram of 9214 bytes exceeds 8192\n\x1b[31mforged")
        return SUCCESS


class Fine(Leaf):
    ticks: ClassVar[int] = 0

    def update(self) -> Status:
        Fine.ticks += 1
        return SUCCESS


TREE = """
root:
  type: Selector
  memory: false
  children:
    - {type: Buggy}
    - {type: Fine}
"""


@pytest.fixture
def bench(tmp_path) -> Bench:
    Buggy.where, Fine.ticks = "update", 0
    return Bench(NodeFactory([Buggy, Fine]).load(write_tree(tmp_path, TREE)))


def test_a_node_that_raises_fails_that_tick_and_the_tree_goes_on(bench, caplog):
    caplog.set_level(logging.ERROR)
    faulted: list[Faulted] = []
    listen(bench, faulted.append, Faulted)
    for _ in range(5):
        assert bench.tick() == SUCCESS  # the selector's next child ran
    assert Fine.ticks == 5
    assert bench.node("Buggy").status == FAILURE
    assert [f.count for f in faulted] == [1, 2, 3, 4, 5]  # recorded every time
    assert faulted[0].where == "Buggy" and faulted[0].what == "its tick"
    assert faulted[0].error.startswith("ValueError: datagram of 9214 bytes")
    assert "\x1b" not in faulted[0].error and "\n" not in faulted[0].error
    logged = [r for r in caplog.records if r.name == "frog_bt.faults"]
    assert len(logged) == 1  # logged once, counted after
    assert "Buggy failed in its tick" in logged[0].getMessage()
    assert bench.core.faults.total == 5


def test_a_failure_that_repeats_raises_an_alert(bench):
    bench.tick(REPEATED - 1)
    now = bench.clock.now()
    assert bench.core.faults.repeated(now) == []
    bench.tick()
    (seen,) = bench.core.faults.repeated(now)
    (condition,) = conditions(
        Facts(now=now, internal_errors=((seen.where, seen.count, seen.error),)), AlertsCfg()
    )
    assert condition.kind == "internal_error" and condition.subject == "Buggy"
    assert "failed 3 times at Buggy: ValueError" in condition.say("en")
    assert "ha fallado 3 veces en Buggy" in condition.say("es")


def test_a_terminate_that_raises_is_counted_and_the_node_is_stopped(tmp_path):
    class BadHalt(Leaf):
        def update(self) -> Status:
            return Status.RUNNING

        def terminate(self, new_status: Status) -> None:
            raise RuntimeError("cancel failed")

    bench = Bench(NodeFactory([BadHalt]).load(write_tree(tmp_path, "root: {type: BadHalt}")))
    bench.tick()
    bench.core.halt()
    assert bench.node("BadHalt").status == Status.INVALID
    assert bench.core.faults.total == 1


def test_an_observer_that_raises_does_not_stop_the_tick(bench, caplog):
    caplog.set_level(logging.ERROR)
    Buggy.where = "nowhere"

    def broken(_event: object) -> None:
        raise KeyError("telemetry bug")

    seen: list[Ticked] = []
    listen(bench, broken, Ticked)
    listen(bench, seen.append, Ticked)
    bench.tick(3)
    assert len(seen) == 3  # the observers after it still hear every event
    assert bench.observers.failures == {("Listener", "KeyError"): 3}
    assert sum("observer Listener failed" in r.getMessage() for r in caplog.records) == 1
