"""Docking: a stale 'failed' from the previous attempt must not fail the next one."""

from __future__ import annotations

from bench import Bench, write_tree

from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS

UNDOCK = "root: {type: Docking, action: undock, timeout: 60}"


def test_undock_succeeds_on_undocked_after_the_command(tmp_path):
    bench = Bench(write_tree(tmp_path, UNDOCK))
    bench.ros("docking_state", "docked")
    assert bench.tick() == RUNNING
    assert bench.take_published() == [("/docking/dock", {"data": "undock"})]
    bench.ros("docking_state", "undocking")
    assert bench.tick() == RUNNING
    bench.ros("docking_state", "undocked")
    assert bench.tick() == SUCCESS


def test_a_republished_failed_from_before_does_not_fail_a_new_attempt(tmp_path):
    bench = Bench(write_tree(tmp_path, UNDOCK))
    bench.ros("docking_state", "failed")  # left over from an earlier attempt
    bench.tick()
    bench.advance(1.0)
    bench.ros("docking_state", "failed")  # re-published at 1 Hz, before the robot reacts
    assert bench.tick() == RUNNING
    bench.ros("docking_state", "undocking")
    bench.tick()
    bench.ros("docking_state", "failed")  # now it is about this attempt
    assert bench.tick() == FAILURE


def test_a_failed_without_busy_state_counts_after_the_grace(tmp_path):
    bench = Bench(write_tree(tmp_path, UNDOCK))
    bench.ros("docking_state", "docked")
    bench.tick()
    bench.advance(2.0)
    bench.ros("docking_state", "failed")
    assert bench.tick() == FAILURE


def test_already_undocked_sends_nothing(tmp_path):
    bench = Bench(write_tree(tmp_path, UNDOCK))
    bench.ros("docking_state", "undocked")
    assert bench.tick() == SUCCESS
    assert bench.take_published() == []


def test_dock_gives_up_after_the_site_timeout_without_a_docked_state(tmp_path):
    bench = Bench(write_tree(tmp_path, "root: {type: Docking, action: dock}"))
    bench.ros("docking_state", "undocked")
    assert bench.tick() == RUNNING
    bench.ros("docking_state", "docking")
    bench.advance(119.9)  # site timeouts.dock is 120 s
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert [i.text for i in bench.core.journal.incidents] == ["dock: no docked within 120 s"]
