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


DOCK = "root: {type: Docking, action: dock}"


def at_shop(bench: Bench, metres: float = 0.0) -> None:
    shop = bench.site.pois["SHOP"]
    bench.pose(shop.x + metres, shop.y)


def test_dock_gives_up_after_the_site_timeout_without_a_docked_state(tmp_path):
    bench = Bench(write_tree(tmp_path, DOCK))
    at_shop(bench)
    bench.ros("docking_state", "undocked")
    assert bench.tick() == RUNNING
    bench.ros("docking_state", "docking")
    bench.advance(119.9)  # site timeouts.dock is 120 s
    assert bench.tick() == RUNNING
    bench.advance(0.1)
    assert bench.tick() == FAILURE
    assert [i.text for i in bench.core.journal.incidents] == ["dock: no docked within 120 s"]


def test_dock_is_sent_only_at_the_docks_waypoint(tmp_path):
    bench = Bench(write_tree(tmp_path, DOCK))
    at_shop(bench, metres=1.9)  # within navigation.tolerance (2 m)
    bench.ros("docking_state", "undocked")
    assert bench.tick() == RUNNING
    assert bench.take_published() == [("/docking/dock", {"data": "dock"})]


def test_dock_asked_away_from_the_dock_fails_at_once_and_sends_nothing(tmp_path):
    bench = Bench(write_tree(tmp_path, DOCK))
    poi2 = bench.site.pois["POI2b"]
    bench.pose(poi2.x, poi2.y)  # 80 m from SHOP
    bench.ros("docking_state", "undocked")
    assert bench.tick() == FAILURE
    assert bench.take_published() == []
    assert bench.core.journal.notes[-1].text == "dock not sent: the robot is 80 m from SHOP"
    assert bench.core.journal.incidents == []  # nothing failed at the dock


def test_dock_with_no_pose_is_not_sent(tmp_path):
    bench = Bench(write_tree(tmp_path, DOCK))
    bench.ros("docking_state", "undocked")
    assert bench.tick() == FAILURE
    assert bench.take_published() == []
