"""Every wait ends, and the last commands arrive: lost events, failing approaches, loss."""

from __future__ import annotations

import asyncio
import itertools
import json
import logging
from collections import Counter

from tour import Running, tour

from frog_bt.model.events import Datagram
from frog_bt.runtime.observer import listen


def test_lost_finish_introduction_asks_anyway_and_the_tour_completes():
    t = tour({"frontend": {"never_sends": ["finish_introduction"]}})
    assert t.outcome.code == 0, t.outcome.reason
    story = t.frontend_commands("start_introduction", "ask_tour", "tour")
    assert story == ["tour started", "start_introduction True", "ask_tour True", "tour ended"]
    intro_at = next(t_ for t_, m in t.sent if m.type == "start_introduction")
    ask_at = next(t_ for t_, m in t.sent if m.type == "ask_tour")
    assert ask_at - intro_at >= t.site.timeouts.introduction  # asked once the wait ran out
    assert t.summary.complete
    assert [i.kind for i in t.summary.incidents] == ["event missing"]


def test_a_visitor_whose_approach_always_fails_gives_way_to_another():
    t = tour(
        {
            "visitors": [
                {"id": 7, "position": [103.0, 36.0], "facing": True, "approach": "failed"},
                {"id": 8, "position": [106.0, 37.5], "facing": True},
            ]
        }
    )
    assert t.outcome.code == 0, t.outcome.reason
    approaches = [c for c in t.ros_commands() if c.startswith("/Approach")]
    assert approaches == ["/ApproachPeopleFar 7", "/ApproachPeopleFar 8"]
    assert t.summary.recruited == [8]
    sent = [at for at, topic in t.published if topic == "/ApproachPeopleFar"]
    assert sent[1] - sent[0] >= t.site.recruit.approach_interval


def test_a_lone_visitor_whose_approach_always_fails_is_tried_once_a_minute():
    async def main() -> list[float]:
        async with Running(
            {
                "visitors": [
                    {"id": 7, "position": [103.0, 36.0], "facing": True, "approach": "failed"}
                ]
            }
        ) as run:
            await run.sim.wait_for(lambda r: r.channel == "/ApproachPeopleFar", 30)
            start = run.sim.clock.now()
            await run.sim.wait_for(lambda r: r.t > start + 300, 30)
            return run.published_at("/ApproachPeopleFar")

    times = asyncio.run(main())
    assert 5 <= len(times) <= 6  # ~300 s of simulated time, 60 s apart (not 1,401 times)
    assert all(b - a >= 60 for a, b in itertools.pairwise(times))


async def _lossy_tour() -> tuple[Running, list[tuple[str, bytes]]]:
    datagrams: list[tuple[str, bytes]] = []
    async with Running({"frontend": {"loss": 0.2}, "seed": 3}, once=True) as run:
        listen(run.executive, lambda e: datagrams.append((e.direction, e.data)), Datagram)
        await run.finish(90)
    return run, datagrams


def test_twenty_percent_loss_each_way_every_part_once_and_tour_ended_acked():
    run, datagrams = asyncio.run(_lossy_tour())
    t = run.tour()
    assert t.outcome.code == 0, t.outcome.reason
    assert run.sim.datagrams_lost > 20  # the loss really happened, both ways
    starts = Counter(
        tuple(r.payload[k] for k in ("poi", "part")) for r in run.sim.received("start_poi")
    )
    assert set(starts.values()) == {1}  # resent until acked, acted on once
    assert {poi for poi, _ in starts} == {"POI1", "POI2", "POI3", "POI4", "POI5", "END"}
    assert [r.payload["state"] for r in run.sim.received("tour")] == ["started", "ended"]
    out = {
        json.loads(d)["seq"]: json.loads(d)
        for direction, d in datagrams
        if direction == "out" and json.loads(d)["type"] != "ack"
    }
    acked = {
        json.loads(d)["seq"]
        for direction, d in datagrams
        if direction == "in" and json.loads(d)["type"] == "ack"
    }
    ended = [seq for seq, m in out.items() if m["type"] == "tour" and m["state"] == "ended"]
    assert len(ended) == 1 and ended[0] in acked  # acked before the executive exited
    assert run.executive.link.pending == 0


def test_a_yes_after_the_answer_timeout_is_ignored_counted_and_logged(caplog):
    # The front end answers 10 s after the site's answer timeout: the visitor has been
    # declined and the robot seeks again. The late "yes" must not start the tour, and it
    # must not vanish either.
    caplog.set_level(logging.WARNING, logger="frog_bt.engine.core")
    visitors = [
        {"id": 7, "position": [103.0, 36.0], "facing": True},
        {"id": 8, "position": [106.0, 37.5], "facing": True, "appear_at": 400},
    ]

    async def main() -> tuple[int, list[str], list[str]]:
        async with Running({"visitors": visitors, "frontend": {"answer_delay": 130}}) as run:
            core = run.executive.core
            await run.executive_ticks_until(lambda: core.stray_answers > 0, 30)
            notes = [n.text for n in core.journal.notes]
            tour = run.tour()
            assert tour.summary.recruited == []  # a "yes" nobody asked for recruits nobody
            assert run.executive.ledger.said_yes == 0
            return core.stray_answers, notes, tour.ros_commands()

    stray, notes, commands = asyncio.run(main())
    assert stray == 1
    assert "visitor 7 gave no answer within 120 s: seek again" in notes
    assert notes[-1] == "the visitor's user_positive came with no question open: ignored"
    assert "/GotoWayPoint POI1a" not in commands  # the tour did not start on it
    assert [r.getMessage() for r in caplog.records] == [
        "the visitor's user_positive came with no question open: ignored (1 so far)"
    ]
