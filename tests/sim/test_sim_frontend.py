"""The simulated front end, sans-I/O, against an executive-side Endpoint."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import pytest

from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import frontend as fm
from frog_bt.sim.frontend import FrontendModel
from frog_bt.sim.scenario import Scenario

HOST = "127.0.0.1"
T0 = 1_780_000_000.0
DT = 0.1


class Link:
    """A FrontendModel and an executive Endpoint wired back to back, stepped by hand."""

    def __init__(self, scenario: Scenario, answer: bool = True) -> None:
        self.traffic: list[tuple[str, str, dict[str, Any]]] = []
        self.model = FrontendModel(
            scenario, HOST, lambda: answer, lambda d, c, f: self.traffic.append((d, c, f))
        )
        self.exe = Endpoint(HOST, fm.EVENTS)
        self.now = T0
        self.steps = 0
        self.events: list[tuple[float, fm.FrontendMessage]] = []
        self.datagrams: list[dict[str, Any]] = []
        self.ack = True
        self.model.start(T0)

    def _deliver(self, datagrams: list[bytes]) -> None:
        for data in datagrams:
            self.datagrams.append(json.loads(data))
            if not self.ack:
                continue
            got = self.exe.receive(data, HOST, self.now)
            if got.message is not None:
                self.events.append((round(self.now - T0, 3), got.message))
            if got.reply is not None:
                self.model.receive(got.reply, HOST, self.now)

    def command(self, message: fm.FrontendMessage) -> list[bytes]:
        replies = self.model.receive(self.exe.send(message, self.now), HOST, self.now)
        self._deliver(replies)
        return replies

    def run(self, seconds: float) -> None:
        for _ in range(round(seconds / DT)):
            self.steps += 1
            self.now = T0 + self.steps * DT
            self._deliver(self.model.step(self.now))

    def types(self) -> list[str]:
        return [m.type for _, m in self.events]


@pytest.fixture
def link(scenario: Callable[..., Scenario]) -> Callable[..., Link]:
    def make(answer: bool = True, **data: Any) -> Link:
        return Link(scenario(**data), answer)

    return make


def test_idle_after_one_second_then_acked(link: Callable[..., Link]) -> None:
    k = link()
    k.run(0.9)
    assert k.events == []
    k.run(0.2)
    assert k.events == [(1.0, fm.FrontendIdle())]
    assert k.model.endpoint.pending == 0
    assert ("in", "ack", {"seq": 1, "type": "frontend_idle"}) in k.traffic


def test_events_are_resent_until_acked(link: Callable[..., Link]) -> None:
    k = link()
    k.ack = False
    k.run(30.0)
    sent = [d for d in k.datagrams if d["type"] == "frontend_idle"]
    assert len(sent) > 50 and {d["seq"] for d in sent} == {1}
    k.ack = True
    k.run(1.0)
    assert k.model.endpoint.pending == 0
    assert [t for t in k.traffic if t[1] == "frontend_idle"] == [
        ("out", "frontend_idle", {})
    ]  # resends are not logged


def test_commands_are_acked_and_logged(link: Callable[..., Link]) -> None:
    k = link()
    replies = k.command(fm.Volume(80))
    assert [json.loads(r) for r in replies] == [{"type": "ack", "seq": 1}]
    assert k.exe.pending == 0
    assert ("in", "volume", {"percent": 80}) in k.traffic
    k2 = link(frontend={"ack": False})
    assert k2.command(fm.Volume(80)) == []


def test_introduction_then_answer(link: Callable[..., Link]) -> None:
    k = link(content={"introduction": 12}, frontend={"answer_delay": 3})
    k.run(2.0)
    k.command(fm.StartIntroduction(True))
    k.run(11.9)
    assert k.types() == ["frontend_idle"]
    k.run(0.2)
    assert k.events[-1] == (14.0, fm.FinishIntroduction())
    k.command(fm.AskTour(True))
    k.run(3.1)
    assert k.events[-1] == (17.1, fm.UserPositive())
    no = link(answer=False)
    no.command(fm.AskTour(None))
    no.run(2.1)
    assert no.types()[-1] == "user_negative"


def test_content_plays_for_its_duration(link: Callable[..., Link]) -> None:
    k = link(content={"default": 10, "POI1": {"a": 4, "b": 6}})
    k.command(fm.StartPoi("POI1", "POI1a", "a"))
    k.run(4.05)
    assert k.events[-1] == (4.0, fm.ContentDone("POI1", "a"))
    k.command(fm.StartPoi("POI1", "POI1a", "b"))
    k.run(6.05)
    assert k.events[-1][1] == fm.ContentDone("POI1", "b")
    k.command(fm.StartPoi("POI3", "POI3", "a"))
    k.run(9.9)
    assert k.events[-1][1] == fm.ContentDone("POI1", "b")
    k.run(0.2)
    assert k.events[-1][1] == fm.ContentDone("POI3", "a")


def test_finish_poi_stops_the_content(link: Callable[..., Link]) -> None:
    k = link()
    k.command(fm.StartPoi("POI4", "POI4", "a"))
    k.run(5.0)
    k.command(fm.FinishPoi("POI4"))
    k.run(60.0)
    assert "content_done" not in k.types()


def test_idle_again_after_a_tour(link: Callable[..., Link]) -> None:
    k = link()
    k.run(2.0)
    k.command(fm.Tour("ended", "done"))
    k.run(5.1)
    assert k.types() == ["frontend_idle", "frontend_idle"]
    never = link(frontend={"idle_after_tour": None})
    never.run(2.0)
    never.command(fm.Tour("ended", "done"))
    never.run(30.0)
    assert never.types() == ["frontend_idle"]


def test_a_restart_numbers_from_one_again(link: Callable[..., Link]) -> None:
    k = link(frontend={"restarts": [20]})
    k.run(2.0)
    k.command(fm.StartPoi("POI4", "POI4", "a"))
    k.run(19.0)
    idles = [d for d in k.datagrams if d["type"] == "frontend_idle"]
    assert [d["seq"] for d in idles] == [1, 1]
    assert "content_done" not in k.types()[:2]


def test_a_silent_front_end_sends_nothing(link: Callable[..., Link]) -> None:
    k = link(frontend={"silent": True})
    assert k.command(fm.StartIntroduction(False)) == []
    k.run(60.0)
    assert k.datagrams == [] and k.events == []
    assert ("in", "start_introduction", {"icl": False}) in k.traffic
