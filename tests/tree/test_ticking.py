"""Pins what the tick fast path relies on: it ticks exactly as BehaviourTree.tick does,
and every status change (ticked or stopped) reaches the core's ``touched`` list."""

from __future__ import annotations

import py_trees
from bench import Bench, write_tree

from frog_bt.tree import ticking
from frog_bt.tree.observed import Selector, Sequence

Status = py_trees.common.Status


def _tree() -> py_trees.trees.BehaviourTree:
    def counter(name: str, n: int, result: Status) -> py_trees.behaviour.Behaviour:
        return py_trees.behaviours.StatusQueue(name, [Status.RUNNING] * n + [result], result)

    root = Selector("root", memory=False, children=[
        Sequence("first", memory=True, children=[counter("a", 2, Status.SUCCESS),
                                                 counter("b", 1, Status.FAILURE)]),
        Sequence("second", memory=True, children=[counter("c", 3, Status.SUCCESS)]),
    ])
    return py_trees.trees.BehaviourTree(root)


def _run(tick) -> list[object]:
    bt = _tree()
    seen: list[object] = []
    bt.add_pre_tick_handler(lambda t: seen.append(("pre", t.count)))
    bt.add_post_tick_handler(lambda t: seen.append(("post", t.count)))
    for _ in range(8):
        tick(bt)
        seen.append(tuple((n.name, n.status) for n in bt.root.iterate()))
    seen.append(bt.count)
    return seen


def test_the_fast_tick_does_what_behaviour_tree_tick_does():
    assert _run(ticking.tick) == _run(py_trees.trees.BehaviourTree.tick)


def test_the_fast_tick_yields_the_nodes_the_tick_reached():
    bt = _tree()
    assert sorted(n.name for n in ticking.tick(bt)) == ["a", "first", "root"]


def test_stopped_nodes_are_reported_with_the_ticked_ones(tmp_path):
    bench = Bench(write_tree(tmp_path, """
        root:
          type: Sequence
          memory: true
          children:
            - {type: WaitEvent, name: waiting, event: finish_introduction, timeout: 10}
        """))
    bench.tick()
    waiting = bench.node("waiting")
    assert waiting.status == Status.RUNNING
    bench.core.halt()  # a stop outside any tick
    assert waiting.status == Status.INVALID
    assert waiting in bench.core.touched and bench.core.bt.root in bench.core.touched
