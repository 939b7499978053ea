"""Case 1: the rosbridge link is lost and comes back, three times in one tour.

Outcome: the executive keeps running; its client reconnects with backoff,
re-advertises and re-subscribes; the pending goal is re-sent; commands issued
while the link is down wait in the client's bounded queue and are delivered
after the reconnect; under sim time the executive's clock stands still while
the link (and so ``/clock``) is down, so nothing times out spuriously; the
tour ends docked.
"""

from __future__ import annotations

import asyncio
import logging

import pytest
from harness import TourRun, arrived, received
from rosmsgs import encode_pose, encode_string

from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.rosbridge.client import RosbridgeClient
from frog_bt.sim.scenario import parse_scenario
from frog_bt.sim.site import load_pois
from frog_bt.sim.world import World

GOTO, DOCK = "/GotoWayPoint", "/docking/dock"
# what the leaves note when they time out, fail, skip, abort or give up


def restored(run: TourRun) -> None:
    """The simulator's one client (the reconnected executive) advertised and subscribed all."""
    (client,) = run.sim.bridge.clients.values()
    assert set(client.subscriptions) == {t.name for t in INPUTS.values()} | {CLOCK.name}
    assert set(client.advertised) == {t.name for t in OUTPUTS.values()}


def test_tour_survives_three_rosbridge_outages() -> None:
    async def main() -> None:
        # 200x: an outage lasts the sim event it waits for plus one backoff step of
        # 0.25 s wall (about 50 s simulated), well inside every timeout.
        async with TourRun({"speed": 200}) as run:
            sim, exe = run.sim, run.executive
            waypoint = run.summary.waypoint_of

            # 1. Driving to POI1: the robot arrives while the link is down, so its
            #    /FROG_response 2 is lost; the re-sent goal is answered 1 then 2.
            r = await sim.wait_for(received(GOTO, where=lambda p: waypoint(p) == "POI1a"), 30)
            first = await run.outage(until=sim.wait_for(arrived(sim, r.t), 30))
            await sim.wait_for(received(GOTO, since=first.sim_up), 30)
            restored(run)  # the frames before that goal on the new connection

            # 2. Content at POI2: the content ends while the link is down, so the goal to
            #    POI3 is published while down; it waits in the queue and goes out on
            #    reconnect.
            await sim.wait_for(
                lambda r: (
                    r.direction == "in" and r.channel == "start_poi" and r.payload["poi"] == "POI2"
                ),
                30,
            )
            n = len(run.events)
            second = await run.outage(
                until=run.wait_event(
                    lambda e: getattr(e, "topic", None) == GOTO and not e.link_up, since=n
                )
            )
            assert waypoint(second.result.msg) == "POI3"
            await sim.wait_for(received(GOTO, since=second.sim_up), 30)
            restored(run)

            # 3. Docking: "docked" is published while the link is down; the 1 Hz docking
            #    state after the reconnect tells the executive.
            r = await sim.wait_for(received(DOCK, where=lambda p: p["data"] == "dock"), 30)
            third = await run.outage(
                until=sim.wait_for(
                    lambda x: (
                        x.direction == "out"
                        and x.channel == "/docking/state"
                        and x.payload["data"] == "docked"
                        and x.t >= r.t
                    ),
                    30,
                )
            )

            outcome = await run.finish()
            assert outcome.code == 0, outcome.reason
            assert outcome.tours == 1
            assert sim.world.docking.state == "docked"
            for outage in (first, second, third):
                assert 0 < outage.seconds < 100, outage

            stats = exe.client.stats
            assert stats.reconnects == 3 and stats.dropped == 0 and stats.malformed == 0

            # No command lost: everything the executive published reached the robot,
            # in order, including what it published while the link was down.
            sent = [(p.topic, p.msg) for p in run.published]
            got = [(x.channel, x.payload) for x in sim.received(side="ros")]
            assert got == sent
            while_down = [p.topic for p in run.published if not p.link_up]
            assert while_down == ["/ICL_command", GOTO], while_down  # face stream off, POI3

            # The pending goal to POI1a was re-sent after the first reconnect, and the
            # robot, already there, answered 1 then 2.
            gotos = [waypoint(p.msg) for p in run.published if p.topic == GOTO]
            assert gotos[:3] == ["POI0", "POI1a", "POI1a"], gotos
            answers = [
                x.payload["data"] for x in sim.log.sent("/FROG_response") if first.sim_down <= x.t
            ]
            assert answers[:3] == [2, 1, 2]  # lost while down, then the re-sent goal's
            assert run.summary.visited == [
                "POI0",
                "POI1a",
                "POI2a",
                "POI3",
                "POI4",
                "POI5",
                "TEMP",
                "END",
                "SHOP",
            ]

            # Nothing timed out, failed or was skipped because the link was down.
            # (typed incidents: a timeout, a failure, a skip, an abort, a lost visitor
            # would each be one)
            assert [(i.kind, i.text) for i in exe.core.journal.incidents] == []
            assert run.commands("tour") == ["tour started", "tour ended"]

    asyncio.run(main())


def test_publishes_beyond_the_queue_while_down_are_dropped_counted_and_logged(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.WARNING, logger="frog_bt.rosbridge")
    client = RosbridgeClient("ws://127.0.0.1:9", queue_limit=10)  # never connected
    client.advertise(DOCK, "std_msgs/String")
    for i in range(25):
        client.publish(DOCK, encode_string(f"cmd {i}"))
    assert client.queued == 10 and client.stats.dropped == 15
    warnings = [r.getMessage() for r in caplog.records]
    assert len(warnings) == 1 and "publish queue full (10), 1 dropped" in warnings[0]


def test_the_simulated_robot_answers_a_goal_it_is_already_at_with_1_then_2() -> None:
    pois = load_pois()
    x, y, qz, qw = pois["POI1a"]
    world = World(parse_scenario({"robot": {"docked": False, "pose": {"x": x, "y": y}}}), pois)
    goal = encode_pose(x, y, qz, qw, world.now)
    for _ in range(2):  # the goal, then the same goal re-sent after a reconnect
        assert world.handle(GOTO, goal) == [("/FROG_response", {"data": 1})]
        assert ("/FROG_response", {"data": 2}) in world.step(0.1)
