"""Tour faults on sim time: abort politely, give up cleanly, resume after a restart."""

from __future__ import annotations

import asyncio
import json
import re
import time

from tour import Running, describe, fast

from frog_bt.config import load_site
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.checkpoint import load as load_checkpoint
from frog_bt.sim.traffic import Record


def commands_after(run: Running, since: float | Record) -> list[str]:
    """What the executive sent from time ``since`` on, or after the record ``since`` (one
    awaited with ``wait_for``: what came after it, even in the same simulated instant)."""
    received = run.sim.received()
    if isinstance(since, Record):
        received = received[next(i for i, r in enumerate(received) if r is since) + 1 :]
    else:
        received = [r for r in received if r.t >= since]
    return [
        describe(r, run.summary)
        for r in received
        if r.channel not in ("ack", "engagement", "volume")
    ]


def is_(channel: str, **fields: object):
    return lambda r: (
        r.direction == "in"
        and r.channel == channel
        and all(r.payload.get(k) == v for k, v in fields.items())
    )


async def _battery_low_during_content() -> tuple[list[str], int, str, str]:
    async with Running({}, once=True) as run:
        started = await run.sim.wait_for(is_("start_poi", poi="POI1", part="a"), 60)
        run.sim.world.battery.percentage = 12.0  # the battery sags mid-content
        outcome = await run.finish()
        return (
            commands_after(run, started),
            outcome.code,
            outcome.reason,
            run.sim.world.docking_state,
        )


def test_battery_low_mid_content_aborts_politely_and_docks():
    after, code, reason, docking = asyncio.run(_battery_low_during_content())
    # in the tick that aborts: content stopped, face stream off, the front end told why;
    # then home to the dock, and nothing else of the tour
    for command in ("finish_poi POI1", "/ICL_command stop", "tour aborted battery 12% below 20%"):
        assert command in after
    assert after.index("/GotoWayPoint SHOP") < after.index("/docking/dock dock")
    assert after[-1] == "/docking/dock dock"
    assert not [c for c in after if c.startswith(("start_poi", "/Approach"))]
    assert [c for c in after if c.startswith("/GotoWayPoint")] == ["/GotoWayPoint SHOP"]
    assert (code, reason, docking) == (1, "tour aborted: battery 12% below 20%", "docked")


async def _battery_low_with_projector_on() -> list[str]:
    async with Running({}, once=True) as run:
        on = await run.sim.wait_for(is_("projector", on=True), 60)
        run.sim.world.battery.percentage = 15.0
        await run.finish()
        return commands_after(run, on.t)


def test_abort_switches_the_projector_off():
    after = asyncio.run(_battery_low_with_projector_on())
    assert after[0] == "projector True"
    assert after.count("projector False") == 1
    assert "tour aborted battery 15% below 20%" in after
    assert after.index("projector False") < after.index("/docking/dock dock") == len(after) - 1


async def _fault() -> tuple[list[str], int, str]:
    async with Running(
        {"faults": [{"at": 120, "name": "motors", "level": 2, "message": "overheated"}]}, once=True
    ) as run:
        outcome = await run.finish()
        return (
            [describe(r, run.summary) for r in run.sim.received("tour")],
            outcome.code,
            outcome.reason,
        )


def test_electronics_fault_aborts_with_its_reason():
    tours, code, reason = asyncio.run(_fault())
    assert tours == ["tour started", "tour aborted electronics fault: motors: overheated"]
    assert (code, reason) == (1, "tour aborted: electronics fault: motors: overheated")


async def _undock_fails() -> tuple[list[str], int, str]:
    async with Running({"docking": {"undock_failures": 5}}, once=True) as run:
        outcome = await run.finish()
        return (
            [c for c in commands_after(run, 0) if not c.startswith("follow")],
            outcome.code,
            outcome.reason,
        )


def test_undocking_failure_is_retried_then_stops_with_a_reason():
    commands, code, reason = asyncio.run(_undock_fails())
    assert commands == [
        "tour started",
        "/docking/dock undock",
        "/docking/dock undock",
        "/docking/dock undock",
    ]  # then it holds and asks for help: with --once, it exits saying why
    assert (code, reason) == (
        1,
        "needs help: The robot could not leave its charger after all its attempts.",
    )


async def _dock_fails() -> tuple[list[str], int, str]:
    async with Running({"docking": {"dock_failures": 5}}, once=True) as run:
        outcome = await run.finish(90)
        return (
            [c for c in commands_after(run, 0) if c.startswith(("/docking", "tour"))],
            outcome.code,
            outcome.reason,
        )


def test_docking_failure_is_retried_then_stops_with_a_reason():
    commands, code, reason = asyncio.run(_dock_fails())
    assert commands[-3:] == ["/docking/dock dock"] * 3  # then it holds and asks for help
    assert (code, reason) == (1, "needs help: The robot could not dock after all its attempts.")


async def _crash_and_resume(tmp_path) -> tuple[list[str], list[str], int, list[str]]:
    checkpoint = tmp_path / "checkpoint.json"
    async with Running({}, checkpoint=checkpoint) as first:
        sim, listen = first.sim, first.listen
        # the executive "crashes" while the visitor watches POI2's content
        await sim.wait_for(is_("start_poi", poi="POI2", part="a"), 60)
        first.own_sim = False
    saved = load_checkpoint(checkpoint)
    assert saved is not None and saved.order == ("start", "recruit", "stop 0")
    assert saved.visitor == 7
    restart_t = sim.clock.now()
    async with Running({}, sim=sim, listen=listen, checkpoint=checkpoint, once=True) as second:
        outcome = await second.finish()
        resumed = commands_after(second, restart_t)
        announced = second.summary.lines()
    await sim.stop()
    return (
        resumed,
        [describe(r, second.summary) for r in sim.received("tour")],
        outcome.code,
        announced,
    )


def test_a_restarted_executive_resumes_the_tour_at_the_current_stop(tmp_path):
    resumed, tours, code, summary = asyncio.run(_crash_and_resume(tmp_path))
    assert code == 0
    resumed_line = next(line for line in summary if line.startswith("resumed:"))
    assert re.fullmatch(r"resumed:   resuming the tour at POI2: checkpoint \d s old", resumed_line)
    gotos = [c for c in resumed if c.startswith("/GotoWayPoint")]
    assert gotos[0] == "/GotoWayPoint POI2a"  # re-navigates to the current stop
    assert "/docking/dock undock" not in resumed and not any(
        c.startswith("/Approach") for c in resumed
    )  # no new start, no new recruitment
    assert tours == ["tour started", "tour ended"]  # one tour, resumed, not a second one
    assert not (tmp_path / "checkpoint.json").exists()  # cleared when the tour ended


async def _battery_low_after_resume(tmp_path) -> tuple[list[str], int, str]:
    checkpoint = tmp_path / "checkpoint.json"
    async with Running({}, checkpoint=checkpoint) as first:
        sim, listen = first.sim, first.listen
        await sim.wait_for(is_("start_poi", poi="POI2", part="a"), 60)
        first.own_sim = False
    async with Running({}, sim=sim, listen=listen, checkpoint=checkpoint, once=True) as second:
        started = await sim.wait_for(is_("start_poi", poi="POI3", part="a"), 60)
        sim.world.battery.percentage = 12.0
        outcome = await second.finish()
        after = commands_after(second, started)
    await sim.stop()
    return after, outcome.code, outcome.reason


def test_a_resumed_tour_is_a_tour_a_low_battery_aborts(tmp_path):
    # the restarted executive sends no new `tour started`, but the tour it carries on is
    # one: the abort guard (and the operator's home) act on it as on any other
    after, code, reason = asyncio.run(_battery_low_after_resume(tmp_path))
    assert "tour aborted battery 12% below 20%" in after
    assert [c for c in after if c.startswith("/GotoWayPoint")] == ["/GotoWayPoint SHOP"]
    assert not [c for c in after if c.startswith("start_poi")]
    assert (code, reason) == (1, "tour aborted: battery 12% below 20%")


async def _fresh_ignores(tmp_path) -> list[str]:
    checkpoint = tmp_path / "checkpoint.json"
    checkpoint.write_text(
        json.dumps(
            {
                "version": 1,
                "done": ["start", "recruit", "stop 0"],
                "visitor": 7,
                "written": time.time(),
            }
        )
    )
    async with Running({}, checkpoint=checkpoint, fresh=True, once=True) as run:
        await run.finish()
        return commands_after(run, 0)


def test_fresh_ignores_the_checkpoint(tmp_path):
    commands = asyncio.run(_fresh_ignores(tmp_path))
    assert commands[:2] == ["tour started", "/docking/dock undock"]


async def _docked_robot_does_not_resume(tmp_path) -> list[str]:
    checkpoint = tmp_path / "checkpoint.json"
    checkpoint.write_text(
        json.dumps(
            {
                "version": 1,
                "done": ["start", "recruit", "stop 0"],
                "visitor": 7,
                "written": time.time(),
            }
        )
    )
    async with Running({}, checkpoint=checkpoint, once=True) as run:
        await run.finish()
        return commands_after(run, 0)


def test_a_checkpoint_is_dropped_when_the_robot_is_docked(tmp_path):
    # a robot at its dock is not in the middle of a tour, whatever the file says
    commands = asyncio.run(_docked_robot_does_not_resume(tmp_path))
    assert commands[:2] == ["tour started", "/docking/dock undock"]


async def _wrong_secret() -> tuple[int, str]:
    async with Rehearsal(
        fast(), site=load_site(), sim_secret="the right one", secret="a wrong one"
    ) as run:
        outcome = await run.finish(30)
        return outcome.code, outcome.reason


def test_once_stops_when_rosbridge_keeps_refusing_the_secret():
    assert asyncio.run(_wrong_secret()) == (
        1,
        "rosbridge refused authentication (check the secret)",
    )
