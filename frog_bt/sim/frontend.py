"""The simulated content front end, sans-I/O: datagrams in, datagrams out.

:class:`FrontendModel` wraps a :class:`~frog_bt.frontend.protocol.Endpoint`
(commands inbound) and scripts what the real Unity front end does, in
simulated time:

* says ``frontend_idle`` ``idle_at`` seconds after the start, again
  ``idle_after_tour`` seconds after a ``tour`` ended or aborted, and after each
  scripted restart (a restart numbers its datagrams from 1 again);
* acks every command (unless ``ack: false``);
* ``start_introduction``: ``finish_introduction`` after the introduction;
* ``ask_tour``: ``user_positive`` or ``user_negative`` after ``answer_delay``,
  as the current visitor's scripted ``answer`` says (positive if none);
* ``start_poi``: ``content_done`` (poi, part) when the part has played; a new
  ``start_poi`` replaces the one playing, ``finish_poi`` stops it;
* resends its events every 0.25 s until acked (:meth:`FrontendModel.step`).

``never_sends`` lists events it never sends (as if a content player broke), and
``loss`` is applied by the simulator to every datagram either way.
``silent: true`` makes it a dead front end: it receives, but never sends.
``silent_from`` / ``silent_between`` (or :meth:`FrontendModel.silence`) make it
hang for a while: it receives (and logs) commands but neither acks nor acts on
them, sends nothing, and its timers wait; when it wakes, what came due goes out.
Every message sent or acted on is reported through ``notify(direction,
channel, fields)`` (resends and duplicates are not).
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import frontend as fm
from frog_bt.sim.scenario import Scenario

log = logging.getLogger(__name__)

EPSILON = 1e-6  # seconds: a timer due at 1.0 fires at a step time of 0.9999999
Notify = Callable[[str, str, dict[str, Any]], None]


@dataclass(slots=True)
class _Timer:
    due: float
    kind: str  # idle | restart | introduction | answer | content
    poi: str = ""
    part: fm.Part | None = None  # a content timer's


class FrontendModel:
    """Scripted front-end behaviour; ``answer()`` says whether the visitor says yes."""

    def __init__(
        self,
        scenario: Scenario,
        peer_host: str,
        answer: Callable[[], bool],
        notify: Notify | None = None,
    ) -> None:
        self.scenario = scenario
        self.spec = scenario.frontend
        self.peer_host = peer_host
        self._answer = answer
        self._notify = notify or (lambda direction, channel, fields: None)
        self.endpoint = self._new_endpoint()
        self.timers: list[_Timer] = []
        self.playing: tuple[str, str] | None = None  # (poi, part)
        self.silences: list[tuple[float, float]] = []  # [start, end) in simulated time
        self.restarts = 0

    def _new_endpoint(self) -> Endpoint:
        # Unlike the executive, the front end keeps resending until acked: the
        # executive may start long after the simulator (in simulated time).
        return Endpoint(self.peer_host, fm.COMMANDS, max_sends=sys.maxsize)

    def start(self, now: float) -> None:
        """Schedule the first ``frontend_idle`` and the scripted restarts."""
        self.timers.append(_Timer(now + self.spec.idle_at, "idle"))
        self.timers += [_Timer(now + t, "restart") for t in self.spec.restarts]
        for start, end in self.spec.silences():
            self.silence(now + start, now + end)

    def silence(self, start: float, end: float) -> None:
        """Hang from ``start`` until ``end`` (simulated time; ``inf``: for ever)."""
        self.silences.append((start, end))

    def silent(self, now: float) -> bool:
        return self.spec.silent or any(a - EPSILON <= now < b - EPSILON for a, b in self.silences)

    # ------------------------------------------------------------ inbound

    def receive(self, data: bytes, host: str, now: float) -> list[bytes]:
        """One datagram from the executive; the datagrams to send in answer."""
        received = self.endpoint.receive(data, host, now)
        if received.error is not None:
            log.warning("malformed datagram from %s: %s", host, received.error)
        if received.acked is not None:
            seq = fm.decode_envelope(data).seq
            self._notify("in", "ack", {"seq": seq, "type": received.acked.type})
        out: list[bytes] = []
        silent = self.silent(now)
        if received.reply is not None and self.spec.ack and not silent:
            out.append(received.reply)
            self._notify("out", "ack", {"seq": fm.decode_envelope(received.reply).seq})
        message = received.message
        if message is not None:
            self._notify("in", message.type, fm.message_fields(message))
            if not silent:
                self._act(message, now)
        return out

    def _act(self, message: fm.FrontendMessage, now: float) -> None:
        if isinstance(message, fm.StartIntroduction):
            self._cancel("introduction")
            self.timers.append(_Timer(now + self.scenario.introduction_seconds, "introduction"))
        elif isinstance(message, fm.AskTour):
            self._cancel("answer")
            self.timers.append(_Timer(now + self.spec.answer_delay, "answer"))
        elif isinstance(message, fm.StartPoi):
            self._cancel("content")
            seconds = self.scenario.content_seconds(message.poi, message.waypoint, message.part)
            self.playing = (message.poi, message.part)
            self.timers.append(_Timer(now + seconds, "content", message.poi, message.part))
        elif isinstance(message, fm.FinishPoi):
            if self.playing is not None and self.playing[0] == message.poi:
                self._cancel("content")
                self.playing = None
        elif isinstance(message, fm.Tour) and message.state in ("ended", "aborted"):
            for kind in ("introduction", "answer", "content"):
                self._cancel(kind)
            self.playing = None
            if self.spec.idle_after_tour is not None:
                self._cancel("idle")
                self.timers.append(_Timer(now + self.spec.idle_after_tour, "idle"))

    def _cancel(self, kind: str) -> None:
        self.timers = [t for t in self.timers if t.kind != kind]

    # ------------------------------------------------------------ time

    def step(self, now: float) -> list[bytes]:
        """Events that are due and resends of unacked ones, at simulated time ``now``."""
        if self.silent(now):
            return []
        now_ish = now + EPSILON
        due = sorted((t for t in self.timers if t.due <= now_ish), key=lambda t: t.due)
        if due:
            self.timers = [t for t in self.timers if t.due > now_ish]
        out = [data for timer in due for data in self._fire(timer, now)]
        return out + self.endpoint.poll(now)

    def _fire(self, timer: _Timer, now: float) -> list[bytes]:
        if timer.kind == "restart":
            return self.restart(now)
        if timer.kind == "idle":
            return self._send(fm.FrontendIdle(), now)
        if timer.kind == "introduction":
            return self._send(fm.FinishIntroduction(), now)
        if timer.kind == "answer":
            yes = self._answer()
            return self._send(fm.UserPositive() if yes else fm.UserNegative(), now)
        self.playing = None
        assert timer.part is not None, "a content timer has its part"
        return self._send(fm.ContentDone(timer.poi, timer.part), now)

    def restart(self, now: float) -> list[bytes]:
        """Restart now: forget everything (numbering from 1 again) and say idle."""
        log.info("front end restarts")
        self.restarts += 1
        self.endpoint = self._new_endpoint()
        self.timers = [t for t in self.timers if t.kind == "restart"]
        self.playing = None
        return self._send(fm.FrontendIdle(), now)

    def _send(self, message: fm.FrontendMessage, now: float) -> list[bytes]:
        if message.type in self.spec.never_sends:
            log.info("front end does not send %s (never_sends)", message.type)
            return []
        data = self.endpoint.send(message, now)
        self._notify("out", message.type, fm.message_fields(message))
        return [data]
