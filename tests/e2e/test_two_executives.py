"""Nothing is global: two executives, each with its own simulator, in one process.

Both tours run at once in one event loop; each executive owns its blackboard, its
trace and its journal, so neither sees the other's visitor, tour state or progress.
"""

from __future__ import annotations

import asyncio

from tour import Running

from frog_bt.model import keys
from frog_bt.model.outcomes import TourState


async def _both() -> tuple[Running, Running]:
    morning = Running({"start_time": "2026-06-01T10:30:00+02:00"}, once=True)
    afternoon = Running(
        {
            "start_time": "2026-06-01T15:10:00+02:00",
            "visitors": [
                {
                    "id": 42,
                    "position": [103.0, 36.0],
                    "facing": True,
                    "answer": "positive",
                    "faces": "engaged",
                    "follow": True,
                }
            ],
        },
        once=True,
    )
    async with morning as a, afternoon as b:
        await asyncio.gather(a.finish(120.0), b.finish(120.0))
        return a, b


def test_two_executives_in_one_process_each_end_their_own_tour() -> None:
    a, b = asyncio.run(_both())
    for run in (a, b):
        outcome = run.executive.outcome
        assert outcome.code == 0, outcome.reason
        assert run.sim.world.docking.state == "docked"
        assert run.summary.complete
        assert run.executive.core.board.get(keys.TOUR_STATE) is TourState.ENDED
    assert a.executive.core.board is not b.executive.core.board
    # each took its own time-of-day variants and its own visitor
    assert a.summary.visited[:3] == ["POI0", "POI1a", "POI2a"]
    assert b.summary.visited[:3] == ["POI0", "POI1b", "POI2b"]
    assert a.executive.core.board.get(keys.VISITOR) != b.executive.core.board.get(keys.VISITOR)


def test_building_another_core_leaves_a_running_one_alone() -> None:
    """What --watch does in its worker thread: load a tree and build a core beside a
    running one. The running core's values and nodes are untouched."""
    from bench import Bench

    from frog_bt.behaviours import load_tree

    running = Bench(load_tree())
    running.tick()
    running.core.board.set(keys.VISITOR, 7)
    before = dict(running.core.board.items())
    other = Bench(load_tree())
    other.tick()
    assert dict(running.core.board.items()) == before
    assert other.core.board.get(keys.VISITOR) is None
    running.tick()
    assert running.core.board.get(keys.VISITOR) == 7
