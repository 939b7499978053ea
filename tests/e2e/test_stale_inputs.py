"""Perception drops out outdoors: stale inputs are never acted on as if fresh (sim time)."""

from __future__ import annotations

import asyncio

from test_faults import commands_after, is_
from tour import Running


async def _laser_drops_out_on_arrival() -> tuple[list[str], list[str], int]:
    async with Running({}, once=True) as run:
        goal = await run.sim.wait_for(is_("/GotoWayPoint"), 60)  # to POI0
        goal = await run.sim.wait_for(lambda r: is_("/GotoWayPoint")(r) and r.t > goal.t, 60)
        run.sim.drop("/PeopleUPO", 3600)  # the laser tracker dies on the way to POI1
        run.sim.drop("/UvA_PersonDetectionAndPose", 3600)
        outcome = await run.finish(90)
        notes = [note.text for note in run.executive.core.journal.notes]
        return commands_after(run, goal.t), notes, outcome.code


def test_laser_drop_out_is_not_taken_for_a_lost_visitor():
    after, notes, code = asyncio.run(_laser_drops_out_on_arrival())
    assert code == 0
    # no tracking at any stop: the robot waits out the grace, then carries on with the
    # visitor rather than abandon them over a sensor drop-out
    assert "laser tracking or pose stale: assuming the visitor follows" in notes
    assert not any(c.startswith("/Approach") for c in after)  # never went back to recruit
    assert [c for c in after if c.startswith("start_poi") and c.endswith(" a")] == [
        "start_poi POI1 POI1a a",
        "start_poi POI2 POI2a a",
        "start_poi POI3 POI3 a",
        "start_poi POI4 POI4 a",
        "start_poi POI5 POI5 a",
        "start_poi END END a",
    ]


async def _pose_drops_out_near_the_shop() -> tuple[list[int], list[str]]:
    async with Running({}, once=True) as run:
        await run.sim.wait_for(is_("tour", state="started"), 60)
        run.sim.drop("/FROG_pose", 60)  # no pose while leaving the shop zone
        start = await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 90)
        volumes = [r.payload["percent"] for r in run.sim.received("volume") if r.t <= start.t]
        notes = [note.text for note in run.executive.core.journal.notes]
        return volumes, notes


def test_volume_is_not_changed_on_a_stale_pose():
    volumes, notes = asyncio.run(_pose_drops_out_near_the_shop())
    # 50% in the shop; the robot left the zone while blind: 100% only once poses are back
    assert volumes == [50, 100]
    assert any(n.startswith("volume 100%") for n in notes)


async def _face_stream_silent() -> tuple[list[str], list]:
    async with Running({}, once=True) as run:
        await run.sim.wait_for(is_("tour", state="started"), 60)
        run.sim.drop("/ICL_FaceDataStream", 3600)  # the face tracker never delivers
        await run.finish(90)
        return run.tour().frontend_commands("ask_tour", "start_poi"), run.summary.decisions


def test_a_silent_face_stream_gives_no_data_not_a_guess():
    commands, decisions = asyncio.run(_face_stream_silent())
    assert all(d.stored == 0 and d.engaged is None for _, d in decisions)
    assert commands[0] == "ask_tour None"  # null: no face data
    assert "start_poi POI1 POI1a b" not in commands  # no extension without data


async def _diagnostics_stop() -> tuple[list[str], int]:
    async with Running({}, once=True) as run:
        await run.sim.wait_for(is_("tour", state="started"), 60)
        run.sim.drop("/diagnostic", 3600)
        run.sim.world.battery.percentage = 5.0  # nobody can see it
        outcome = await run.finish(90)
        return run.tour().frontend_commands("tour"), outcome.code


def test_stale_diagnostics_do_not_abort_or_reassure():
    # a battery the executive cannot see does not abort the tour on a guess
    tours, code = asyncio.run(_diagnostics_stop())
    assert (tours, code) == (["tour started", "tour ended"], 0)
