"""``frog-bt run --watch``: a valid change to the tree takes over at the next idle point
(docked, no tour running); a bad one is reported and the running tree stays."""

from __future__ import annotations

import asyncio
import gc
import shutil
from pathlib import Path

from tour import Running, after_ticks

from frog_bt import resources
from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.model import keys
from frog_bt.model.outcomes import TourState
from frog_bt.runtime.memory import HeapKeeper
from frog_bt.runtime.watch import Watch

WAIT = "Wait for the front end"


def copy_trees(tmp_path: Path) -> Path:
    shutil.copytree(resources.tree_dir(), tmp_path / "trees")
    return tmp_path / "trees" / "tour.yaml"


def names(tree) -> set[str]:
    return {n.name for n in tree.nodes()}


def test_a_valid_change_takes_over_when_idle_and_a_bad_one_is_refused(tmp_path: Path) -> None:
    tour_file = copy_trees(tmp_path)
    site = load_site()
    tree = load_tree(tour_file, site)

    async def main() -> None:
        # The front end never says it is idle: the robot stays docked, no tour starts.
        async with Running(
            {"dt": 0.1, "frontend": {"idle_at": 10_000}}, site=site, tree=tree
        ) as run:
            exe = run.executive
            keeper = HeapKeeper()  # as `run --watch` attaches it (frog_bt.runtime.memory)
            exe.observers.attach(exe, [keeper])
            refused: list[list[str]] = []
            watch = Watch(tour_file, None, tree, exe.offer, refuse=refused.append)
            assert await watch.check() is None  # nothing changed

            await run.sim.wait_for(lambda r: r.channel == "/docking/state", 30)
            # until the executive has ticked, docked and idle
            await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
            assert exe.idle()

            # A bad save: reported (file and line), the running tree stays.
            recruit = tour_file.parent / "recruit.yaml"
            good = recruit.read_text()
            recruit.write_text(good.replace("      - {type: SeekVisitor}\n", ""))
            assert await watch.check() is False
            assert len(refused) == 1 and "recruit.yaml:17:9:" in refused[0][0]
            assert await watch.check() is None  # reported once, not at every poll
            assert exe.core.tree is tree

            # A valid save: checked, then swapped in at the next tick (docked and idle).
            recruit.write_text(good)
            text = tour_file.read_text()
            tour_file.write_text(text.replace(f"name: {WAIT}", f"name: {WAIT} again"))
            assert await watch.check() is True
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.swaps > 0)
            assert exe.swaps == 1 and ticks >= 1
            assert f"{WAIT} again" in names(exe.core.tree) and exe.core.tree is not tree
            # and the new tree runs: it waits for the front end
            await after_ticks(exe, lambda: exe.core.ticks > 0)
            tip = exe.core.root.tip()
            assert tip is not None and tip.name == f"{WAIT} again"
            # the heap was frozen again once, after the tick that swapped the tree in
            assert keeper.refrozen == 1

    try:
        asyncio.run(main())
    finally:
        gc.unfreeze()  # what the keeper froze in this test's process


def test_no_swap_while_a_tour_runs(tmp_path: Path) -> None:
    tour_file = copy_trees(tmp_path)
    site = load_site()
    tree = load_tree(tour_file, site)

    async def main() -> None:
        async with Running({}, site=site, tree=tree) as run:
            exe = run.executive
            await run.sim.wait_for(
                lambda r: r.channel == "tour" and r.payload.get("state") == "started", 30
            )
            exe.offer(site, load_tree(tour_file, site))
            await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 30)
            assert exe.core.board.get(keys.TOUR_STATE) is TourState.STARTED and not exe.idle()
            assert exe.swaps == 0 and exe.core.tree is tree

    asyncio.run(main())


def test_a_change_of_links_or_topics_is_refused_it_takes_a_restart(tmp_path: Path) -> None:
    tour_file = copy_trees(tmp_path)
    site = load_site()
    tree = load_tree(tour_file, site)
    renamed = site.model_copy(update={"topics": {"pose": "/robot/pose"}})

    async def main() -> None:
        async with Running(
            {"dt": 0.1, "frontend": {"idle_at": 10_000}}, site=site, tree=tree
        ) as run:
            exe = run.executive
            # docked and idle: a valid offer would be swapped now
            await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
            assert exe.idle()
            exe.offer(renamed, load_tree(tour_file, renamed))
            ticks = exe.core.ticks
            await after_ticks(exe, lambda: exe.core.ticks >= ticks + 5)  # idle ticks went by
            assert exe.swaps == 0 and exe.core.tree is tree

    asyncio.run(main())


# ------------------------------------------------------------------ what outlives a tree


def test_a_reload_keeps_what_people_decided(tmp_path: Path) -> None:
    """Out of service, an acknowledged alert, the front end's events and the decision
    journal: a reload builds a new core and keeps every one of them."""
    tour_file = copy_trees(tmp_path)
    site = load_site()
    tree = load_tree(tour_file, site)

    async def main() -> None:
        async with Running(
            {"dt": 0.1, "frontend": {"idle_at": 10_000}}, site=site, tree=tree
        ) as run:
            exe = run.executive
            await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
            assert (await exe.staff.submit(Command.SERVICE_OFF)).ok
            run.sim.world.battery.percentage = 20.0  # below alerts.battery_below
            await after_ticks(exe, lambda: "battery_low" in exe.staff.book.active)
            assert (await exe.staff.submit(Command.ACK_ALERT, "battery_low")).ok
            notes = len(exe.core.journal.notes)
            old = exe.core

            exe.offer(site, load_tree(tour_file, site))
            await after_ticks(exe, lambda: exe.swaps == 1)
            core = exe.core
            assert core is not old and core.board.get(keys.IN_SERVICE) is False
            assert core.journal is old.journal and len(core.journal.notes) > notes  # kept
            assert any("tree reloaded" in n.text for n in core.journal.notes)
            book = exe.staff.book  # still up, and still acknowledged: not shown again
            assert "battery_low" in book.active and "battery_low" not in book.unacknowledged
            answer = await exe.staff.submit(Command.SERVICE_OFF)
            assert not answer.ok and "already out of service" in answer.text

    asyncio.run(main())


def test_a_reload_keeps_a_pause_and_its_timer() -> None:
    """Two cores of one executive share its standing state: a pause set on the first is
    the second's, and its bound still counts from when it was asked for."""
    from bench import Bench

    from frog_bt.engine.core import Core

    bench = Bench(load_tree(None, load_site()))
    first = bench.core
    first.board.set(keys.TOUR_STATE, TourState.STARTED)
    assert first.command(Command.PAUSE).ok
    paused_at = bench.clock.now()
    second = Core(
        bench.site,
        load_tree(None, bench.site),
        bench.clock,
        first._publish_topic,
        first._send,
        standing=first.standing,
    )
    assert second.board.get(keys.PAUSED) is True
    assert second.operator.paused_since == paused_at
    assert not second.command(Command.PAUSE).ok  # already paused, in the new tree too
    bench.clock.advance(bench.site.operator.pause_max)
    reason = second.operator.check_pause(bench.clock.now())
    assert reason is not None and "paused longer than" in reason.text


def test_run_watch_rerun_the_viewer_follows_a_reloaded_tree(tmp_path: Path) -> None:
    """``run --watch --rerun save:``: telemetry attached as ``run`` attaches it (its writer
    process); after the reload the file has the new tree (graph, lanes, running path)
    beside the first, a layout that opens on it, and a bookmark at the reload."""
    from rerun.chunk import RrdReader

    from frog_bt.commands.run import attach_observers
    from frog_bt.runtime.observer import close_all

    tour_file = copy_trees(tmp_path)
    site = load_site()
    tree = load_tree(tour_file, site)
    rrd = tmp_path / "watch.rrd"

    async def main() -> None:
        async with Running(
            {"dt": 0.1, "frontend": {"idle_at": 10_000}}, site=site, tree=tree
        ) as run:
            exe = run.executive
            observers = attach_observers(exe, record=None, rerun=f"save:{rrd}")
            try:
                watch = Watch(tour_file, None, tree, exe.offer)
                await run.sim.wait_for(lambda r: r.channel == "/docking/state", 30)
                await after_ticks(exe, lambda: bool(exe.core.ticks and exe.idle()))
                text = tour_file.read_text()
                tour_file.write_text(text.replace(f"name: {WAIT}", f"name: {WAIT} again"))
                assert await watch.check() is True
                await after_ticks(exe, lambda: exe.swaps > 0)
                ticks = exe.core.ticks
                await after_ticks(exe, lambda: exe.core.ticks > ticks + 3)
            finally:
                close_all(observers)

    asyncio.run(main())
    chunks: dict[str, list] = {}
    reader = RrdReader(rrd)
    for chunk in reader.stream():
        chunks.setdefault(str(chunk.entity_path), []).append(chunk)

    def values(entity: str, component: str, static: bool = False) -> list:
        out: list = []
        for chunk in chunks.get(entity, ()):
            batch = chunk.to_record_batch()
            if chunk.is_static == static and component in batch.schema.names:
                out += batch.column(component).to_pylist()
        return out

    first = values("/bt/graph", "GraphNodes:labels", static=True)
    second = values("/bt/tree2/graph", "GraphNodes:labels", static=True)
    assert first and second
    assert f"{WAIT} again" in second[-1] and f"{WAIT} again" not in first[-1]
    # the new tree's lanes and running path follow it from the reload on
    lanes = [p for p in chunks if p.startswith("/bt/tree2/status/")]
    assert any(values(p, "StateChange:state") for p in lanes)
    paths = values("/bt/tree2/path", "GraphNodes:labels")
    assert paths and any(f"{WAIT} again" in labels for labels in paths)
    [mark] = values("/log/bookmarks/reload", "TextLog:text")
    assert "tree reloaded" in mark[0]
    # the last layout sent opens on the new tree
    origins = []
    for blueprint in reader.blueprints():
        for chunk in reader.stream(store=blueprint):
            batch = chunk.to_record_batch()
            if "ViewBlueprint:space_origin" in batch.schema.names:
                origins += [o[0] for o in batch.column("ViewBlueprint:space_origin").to_pylist()]
    assert "/bt/tree2/path" in origins
