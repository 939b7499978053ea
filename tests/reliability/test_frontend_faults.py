"""Case 2: a front end that never acks, goes silent for a while, or restarts mid-tour.

Outcomes:

* never acks: every command is sent 8 times in all (resent every 0.25 s), then
  given up with one warning each; the tour completes;
* silent for a while (hung: no acks, no events, commands not acted on): a content
  part waits for its ``content_done`` until the stop's ``content_timeout`` (or
  ``timeouts.content``), then the tour goes on; the late ``content_done`` sent when
  the front end wakes is ignored; the tour completes;
* restarts (numbers from seq 1 again, says ``frontend_idle``): no second tour
  starts, and its new events are acted on, not swallowed as duplicates of the old
  instance's seqs (:class:`~frog_bt.frontend.protocol.Endpoint` recognises the
  restart and forgets the seqs it saw).
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
import yaml
from harness import TourRun, received

from frog_bt.config import DEFAULT_CONFIG, Site, load_site
from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import frontend as fm
from frog_bt.model.events import Datagram, FrontendIn
from frog_bt.runtime.observer import listen
from frog_bt.sim.frontend import FrontendModel
from frog_bt.sim.scenario import parse_scenario

STOPS = ["POI1", "POI2", "POI3", "POI4", "POI5", "END"]


def short_timeouts(tmp_path: Path, content: float, **per_stop: float) -> Site:
    """A copy of config/site.yaml with ``timeouts.content`` and per-stop content timeouts."""
    data = yaml.safe_load(DEFAULT_CONFIG.read_text(encoding="utf-8"))
    data["timeouts"]["content"] = content
    for stop in data["tour"]["stops"]:
        if stop["poi"] in per_stop:
            stop["content_timeout"] = per_stop[stop["poi"]]
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return load_site(path)


def content_timeouts(run: TourRun) -> list[str]:
    notes = run.executive.core.journal.notes
    return [note.text for note in notes if "no content_done" in note.text]


def tour_states(run: TourRun) -> list[str]:
    return run.commands("tour")


# ------------------------------------------------------------------ never acks


def test_front_end_that_never_acks_gets_eight_sends_then_a_warning(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.WARNING, logger="frog_bt.frontend")

    async def main() -> None:
        async with TourRun({"frontend": {"ack": False}}) as run:
            sends: Counter[int] = Counter()

            def count(event: Datagram) -> None:
                obj = json.loads(event.data)
                if event.direction == "out" and obj["type"] != "ack":
                    sends[obj["seq"]] += 1

            listen(run.executive, count, Datagram)
            outcome = await run.finish()
            assert outcome.code == 0, outcome.reason
            stats, pending = run.executive.link.stats, run.executive.link.pending
            assert stats.acked == 0 and stats.sent > 20
            assert stats.unacked + pending == stats.sent  # given up, or still trying at exit
            given_up = [seq for seq, n in sends.items() if n == 8]
            assert len(given_up) == stats.unacked
            assert max(sends.values()) == 8
            warnings = [r for r in caplog.records if "never acked" in r.getMessage()]
            assert len(warnings) == stats.unacked
            # the front end still played everything, each command acted on once
            assert tour_states(run) == ["tour started", "tour ended"]
            starts = [c.split()[1] for c in run.commands("start_poi") if c.endswith(" a")]
            assert starts == STOPS
            assert content_timeouts(run) == []

    asyncio.run(main())


# ------------------------------------------------------------------ silent for a while


def test_front_end_silent_mid_tour_content_ends_by_timeout(tmp_path: Path) -> None:
    site = short_timeouts(tmp_path, content=20, POI2=15)
    # At the robot's real speed: the drive to POI3 outlasts the front end's 60 s silence.
    slow = {"navigation": {"speed": 0.6}}

    async def main() -> None:
        async with TourRun(site=site, scenario=slow) as run:
            sim = run.sim
            # POI2's content starts playing, then the front end hangs for 60 s.
            r = await sim.wait_for(received("start_poi", where=lambda p: p["poi"] == "POI2"), 30)
            sim.silence_frontend(60)
            woke = r.t + 60
            outcome = await run.finish()
            assert outcome.code == 0, outcome.reason
            assert sim.world.docking.state == "docked"
            assert tour_states(run) == ["tour started", "tour ended"]

            # POI2 waited its own content_timeout (15 s) for each part it played, then
            # went on; no other stop timed out.
            timeouts = content_timeouts(run)
            assert timeouts and all(
                t.startswith("POI2 part") and "within 15 s" in t for t in timeouts
            ), timeouts
            starts = [c.split()[1] for c in run.commands("start_poi") if c.endswith(" a")]
            assert starts == STOPS

            # The content_done of POI2 a went out late, when the front end woke, and
            # changed nothing: POI3's content waited for its own.
            late = [
                x
                for x in sim.log.sent("content_done", side="frontend")
                if x.payload["poi"] == "POI2"
            ]
            assert late and late[0].t >= woke - 0.2
            # Commands sent while it was silent were resent, then given up.
            assert run.executive.link.stats.unacked >= 2

    asyncio.run(main())


# ------------------------------------------------------------------ restart


def test_front_end_restart_mid_tour_starts_no_second_tour() -> None:
    async def main() -> None:
        async with TourRun() as run:
            sim, exe = run.sim, run.executive
            heard: list[str] = []
            listen(exe, lambda e: heard.append(e.message.type), FrontendIn)
            await sim.wait_for(
                received(
                    "/GotoWayPoint",
                    since=0.0,
                    where=lambda p: run.summary.waypoint_of(p) == "POI1a",
                ),
                30,
            )
            sim.restart_frontend()
            outcome = await run.finish()
            assert outcome.code == 0, outcome.reason
            assert sim.frontend.restarts == 1
            assert tour_states(run) == ["tour started", "tour ended"]
            assert exe.link.stats.peer_restarts == 1
            # every event the front end sent (before and after its restart) was acted on
            sent = [x.channel for x in sim.log.sent(side="frontend") if x.channel != "ack"]
            assert heard == sent
            assert sent.count("frontend_idle") == 2
            assert content_timeouts(run) == []
            starts = [c.split()[1] for c in run.commands("start_poi") if c.endswith(" a")]
            assert starts == STOPS

    asyncio.run(main())


# ------------------------------------------------------------------ sans-I/O: the sim's
# own front end against an executive Endpoint, stepped by hand on simulated time.

T0 = 1_780_000_000.0
HOST = "127.0.0.1"


class Wire:
    """A FrontendModel and the executive's Endpoint back to back."""

    def __init__(self, **scenario: Any) -> None:
        self.model = FrontendModel(parse_scenario(scenario), HOST, lambda: True)
        self.exe = Endpoint(HOST, fm.EVENTS)
        self.now = T0
        self.events: list[tuple[float, fm.FrontendMessage]] = []
        self.acks = 0
        self.model.start(T0)

    def deliver(self, datagrams: list[bytes]) -> None:
        for data in datagrams:
            got = self.exe.receive(data, HOST, self.now)
            if got.message is not None:
                self.events.append((round(self.now - T0, 1), got.message))
            if got.reply is not None:
                self.model.receive(got.reply, HOST, self.now)

    def command(self, message: fm.FrontendMessage) -> None:
        replies = self.model.receive(self.exe.send(message, self.now), HOST, self.now)
        self.acks += sum(json.loads(d)["type"] == "ack" for d in replies)
        self.deliver(replies)

    def run(self, seconds: float) -> None:
        end = self.now + seconds - 1e-9
        while self.now < end:
            self.now = round(self.now + 0.1, 6)
            self.deliver(self.model.step(self.now))

    def since(self, t: float) -> list[fm.FrontendMessage]:
        return [m for at, m in self.events if at >= t]


def test_events_of_a_restarted_front_end_are_not_taken_for_duplicates() -> None:
    # Short content: the old instance's seqs 2..4 are seen within the last 10 s when
    # the restarted one sends its own seqs 2..4.
    w = Wire(content={"default": 1.0}, frontend={"restarts": [6.0]})
    w.run(1.5)  # frontend_idle, seq 1
    for poi in ("POI3", "POI4", "POI5"):
        w.command(fm.StartPoi(poi, poi, "a"))
        w.run(1.2)  # content_done, seqs 2, 3, 4
    w.run(6.0 - (w.now - T0))
    for poi in ("POI3", "POI4", "POI5"):
        w.command(fm.StartPoi(poi, poi, "a"))
        w.run(1.2)
    assert [type(m).__name__ for m in w.since(6.0)] == [
        "FrontendIdle",
        "ContentDone",
        "ContentDone",
        "ContentDone",
    ]
    assert w.exe.stats.peer_restarts == 1 and w.exe.stats.duplicates == 0


@pytest.mark.parametrize("silent", [{"silent_between": [[3.0, 8.0]]}, {"silent_from": 3.0}])
def test_silent_interval_no_acks_no_events_then_late_events(silent: dict[str, Any]) -> None:
    w = Wire(content={"default": 1.0}, frontend=silent)
    w.run(2.0)
    assert [m.type for _, m in w.events] == ["frontend_idle"]
    w.command(fm.StartPoi("POI3", "POI3", "a"))  # acked, plays 1 s
    w.run(2.0)  # content_done at 3.0 s: it is hung by then
    w.command(fm.StartPoi("POI4", "POI4", "a"))  # hung: no ack, not played
    assert w.acks == 1 and w.events[1:] == []
    w.run(10.0)
    if "silent_from" in silent:
        assert w.events[1:] == []
    else:  # wakes at 8 s: the content_done it owed goes out then; POI4 was never played
        assert w.events[1:] == [(8.0, fm.ContentDone("POI3", "a"))]


def test_silent_between_must_be_ordered() -> None:
    from frog_bt.errors import ConfigError

    with pytest.raises(ConfigError, match=r"frontend\.silent_between\[0\]: .*end > start"):
        parse_scenario({"frontend": {"silent_between": [[5, 5]]}})
