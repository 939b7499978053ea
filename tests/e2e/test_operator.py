"""Operator commands in whole simulated tours: each does what it says at the right point
of a tour, and each refusal changes nothing.

Commands are applied between ticks (``core.command``), as the executive does with what
the console and ``frog-bt ctl`` queue.
"""

from __future__ import annotations

import asyncio

from test_faults import commands_after, is_
from tour import Running

from frog_bt.engine.operator import Command
from frog_bt.model import keys
from frog_bt.model.outcomes import IncidentKind


def sent_(channel: str, **fields: object):
    """A message the simulated front end sent (content_done, frontend_idle)."""
    return lambda r: (
        r.direction == "out"
        and r.channel == channel
        and all(r.payload.get(k) == v for k, v in fields.items())
    )


async def _home_mid_content() -> tuple[list[str], int, str, str, str]:
    async with Running({}, once=True) as run:
        started = await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
        answer = run.executive.core.command(Command.HOME)
        again = run.executive.core.command(Command.HOME)
        outcome = await run.finish()
        return (
            commands_after(run, started),
            outcome.code,
            outcome.reason,
            answer.text,
            again.text if not again.ok else "applied twice",
        )


def test_home_ends_the_tour_politely_with_reason_operator_and_docks() -> None:
    after, code, reason, did, again = asyncio.run(_home_mid_content())
    assert did == "ending the tour: the robot goes home and docks"
    assert again == "the tour is already ending: the robot is going home"
    for command in ("finish_poi POI1", "/ICL_command stop", "tour aborted operator"):
        assert command in after
    assert [c for c in after if c.startswith("/GotoWayPoint")] == ["/GotoWayPoint SHOP"]
    assert after[-1] == "/docking/dock dock"
    assert not [c for c in after if c.startswith(("start_poi", "/Approach"))]
    assert (code, reason) == (1, "tour aborted: operator")


async def _skip_at(poi: str, event: str) -> tuple[list[str], str, list[str]]:
    async with Running({}, once=True) as run:
        if event == "drive":
            await run.sim.wait_for(
                lambda r: (
                    r.channel == "/GotoWayPoint"
                    and run.summary.waypoint_of(r.payload).startswith(poi)
                ),
                60,
            )
        else:
            await run.sim.wait_for(is_("start_poi", poi=poi, part="a"), 60)
        t = run.sim.clock.now()
        answer = run.executive.core.command(Command.SKIP)
        outcome = await run.finish()
        assert outcome.code == 0, outcome.reason
        skipped = [
            i.subject
            for i in run.executive.core.journal.incidents
            if i.kind is IncidentKind.STOP_LEFT
        ]
        return commands_after(run, t), answer.text, skipped


def test_skip_during_content_leaves_the_stop_and_goes_on_with_the_next() -> None:
    after, did, skipped = asyncio.run(_skip_at("POI2", "content"))
    assert did == "skipping POI2: on to the next stop"
    assert skipped == ["POI2"]
    assert after.index("finish_poi POI2") < after.index("/GotoWayPoint POI3")
    assert "start_poi POI2 POI2a b" not in after  # no extension of a skipped stop
    assert "tour ended" in after


def test_skip_during_the_drive_goes_straight_on_to_the_next_stop() -> None:
    after, did, skipped = asyncio.run(_skip_at("POI3", "drive"))
    assert did == "skipping POI3: on to the next stop"
    assert skipped == ["POI3"]
    assert not [c for c in after if c.startswith("start_poi POI3")]
    assert next(c for c in after if c.startswith("/GotoWayPoint")) == "/GotoWayPoint POI4"


async def _refusals() -> list[tuple[bool, str]]:
    async with Running({}, once=True) as run:
        core = run.executive.core
        await run.sim.wait_for(is_("tour", state="started"), 60)
        # docked, undocking: no stop yet
        answers = [
            core.command(Command.SKIP),
            core.command(Command.RESUME),
            core.command(Command.SERVICE_ON),
        ]
        assert core.board.get(keys.SKIP) is None and core.board.get(keys.IN_SERVICE)
        await run.finish()
        answers += [core.command(Command.HOME), core.command(Command.PAUSE)]
        return [(a.ok, a.text) for a in answers]


def test_refusals_say_why_and_change_nothing() -> None:
    assert asyncio.run(_refusals()) == [
        (False, "not at a stop or driving to one: nothing to skip"),
        (False, "not paused"),
        (False, "already in service"),
        (False, "no tour is running: the robot is at the dock or going there"),
        (False, "no tour is running (service_off keeps the robot docked)"),
    ]


async def _pause_then_resume() -> tuple[list[str], list[str], float]:
    async with Running({}, once=True) as run:
        core = run.executive.core
        await run.sim.wait_for(is_("start_poi", poi="POI3", part="a"), 60)
        assert core.command(Command.PAUSE).ok
        done = await run.sim.wait_for(sent_("content_done", poi="POI3"), 60)
        # held for 60 s of sim time: the drive to POI4 does not start
        await run.sim.clock.sleep_until(done.t + 60.0)
        held = commands_after(run, done.t)
        resumed_at = run.sim.clock.now()
        assert core.command(Command.RESUME).ok
        outcome = await run.finish()
        assert outcome.code == 0, outcome.reason
        return held, commands_after(run, resumed_at), resumed_at


def test_pause_holds_at_the_next_step_and_resume_goes_on() -> None:
    held, after, _ = asyncio.run(_pause_then_resume())
    assert not [c for c in held if c.startswith(("/GotoWayPoint", "start_poi"))]
    assert after[0] == "/GotoWayPoint POI4"
    assert after[-2:] == ["/docking/dock dock", "tour ended"]


async def _pause_runs_out() -> tuple[list[str], str, float, float]:
    async with Running({}, once=True) as run:
        core = run.executive.core
        core.operator.pause_max = 30.0
        await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
        assert core.command(Command.PAUSE).ok
        # the executive's own clock at the pause (the sim's may be ahead of it under load)
        paused_at = core.operator.paused_since
        assert paused_at is not None
        outcome = await run.finish()
        aborted = next(r for r in run.sim.received("tour") if r.payload["state"] == "aborted")
        return commands_after(run, paused_at), outcome.reason, paused_at, aborted.t


def test_a_pause_longer_than_the_bound_ends_the_tour_politely() -> None:
    after, reason, paused_at, aborted_at = asyncio.run(_pause_runs_out())
    assert reason == "tour aborted: paused longer than 30 s"
    assert 30.0 <= aborted_at - paused_at < 32.0
    assert after[-1] == "/docking/dock dock"


async def _service_off() -> tuple[list[str], bool, list[str]]:
    async with Running({}, once=False) as run:
        core = run.executive.core
        await run.sim.wait_for(is_("start_poi", poi="POI4", part="a"), 60)
        assert core.command(Command.SERVICE_OFF).text == (
            "out of service: this tour finishes, then no new tour starts"
        )
        ended = await run.sim.wait_for(is_("tour", state="ended"), 60)
        idle = await run.sim.wait_for(sent_("frontend_idle"), 60)
        await run.sim.clock.sleep_until(idle.t + 120.0)  # a front end ready, two minutes
        quiet = commands_after(run, ended.t)
        in_service = core.board.get(keys.IN_SERVICE)
        assert core.command(Command.SERVICE_ON).ok
        back = await run.sim.wait_for(is_("tour", state="started"), 60)
        run.executive.stop("test over")
        await run.finish()
        return quiet, bool(in_service), commands_after(run, back.t - 0.001)[:1]


def test_service_off_finishes_the_tour_then_starts_none_until_service_on() -> None:
    quiet, in_service, restarted = asyncio.run(_service_off())
    assert not in_service
    assert not [c for c in quiet if c.startswith(("tour started", "/docking/dock undock"))]
    assert restarted == ["tour started"]


async def _pause_while_recruiting() -> tuple[list[str], list[str], list[str], int]:
    """Pause while the robot seeks at POI0 (a visitor then appears, facing it), resume;
    pause again as the introduction plays (its content_done comes while paused),
    resume."""
    from frog_bt.sim.people import PRESENT
    from frog_bt.tree.leaf import RUNNING

    hidden = {
        "id": 7,
        "position": [103.0, 36.0],
        "facing": True,
        "answer": "positive",
        "faces": "engaged",
        "follow": True,
        "after_tour": "return",
        "appear_at": "never",
    }
    async with Running({"visitors": [hidden]}, once=True) as run:
        core, clock = run.executive.core, run.sim.clock
        bound = clock.now() + 600.0
        while not any(n.status is RUNNING for n in core.seekers):
            assert clock.now() < bound, "the robot never sought a visitor"
            await clock.sleep_until(clock.now() + 0.5)
        assert core.command(Command.PAUSE).ok
        paused_at = clock.now()
        run.sim.world.crowd.visitors[7].state = PRESENT  # someone faces the robot now
        await clock.sleep_until(paused_at + 60.0)
        seeking = commands_after(run, paused_at)
        resumed_at = clock.now()
        assert core.command(Command.RESUME).ok
        await run.sim.wait_for(is_("start_introduction"), 120)
        assert core.command(Command.PAUSE).ok
        paused_at = clock.now()
        await clock.sleep_until(paused_at + 60.0)  # the introduction (3 s) ends meanwhile
        introducing = commands_after(run, paused_at)
        assert core.command(Command.RESUME).ok
        outcome = await run.finish()
        return seeking, commands_after(run, resumed_at), introducing, outcome.code


def test_pause_holds_the_approach_and_the_question_to_the_visitor() -> None:
    """CONTRACT §7: no new goal and no new content until resume, when recruiting too."""
    seeking, after, introducing, code = asyncio.run(_pause_while_recruiting())
    assert not [c for c in seeking if c.startswith(("/Approach", "start_introduction"))]
    assert after[0].startswith("/ApproachPeopleFar")  # resumed: the visitor is approached
    assert not [c for c in introducing if c.startswith(("ask_tour", "/GotoWayPoint POI1"))]
    assert [c for c in after if c.startswith("ask_tour")]  # asked once resumed
    assert code == 0
