"""Commands to the robot over rosbridge, and the one request awaiting ``/FROG_response``.

``/GotoWayPoint`` and ``/ApproachPeopleFar`` share ``/FROG_response`` and carry
no goal id, so at most one of them is pending at a time: a new goal replaces
the active one (CONTRACT §1), and a response that arrives while nothing is
pending is stale and ignored. Responses are applied to the pending
:class:`Request` in the pre-tick snapshot, so every tick sees one consistent
state.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from frog_bt.config import Poi
from frog_bt.kernel.clock import Clock
from frog_bt.rosbridge.msgs import Pose
from frog_bt.wire import ABORTED, ACTIVE, FAILED, SUCCEEDED

log = logging.getLogger(__name__)
TERMINAL = (SUCCEEDED, FAILED, ABORTED)
CODE_NAMES = {ACTIVE: "active", SUCCEEDED: "succeeded", FAILED: "failed", ABORTED: "aborted"}


@dataclass(slots=True)
class Request:
    """A goal or approach sent to the robot; ``code`` is the latest response (0: none yet)."""

    id: int
    kind: str  # "goto" | "approach"
    target: str
    sent_at: float
    value: Any = None  # as published, for a re-send
    code: int = 0
    answered_at: float | None = None

    @property
    def done(self) -> bool:
        return self.code in TERMINAL


Publish = Callable[[str, Any], None]  # (output role, value: the wire table encodes it)


class Actions:
    """Publishes robot commands by role (``goto``, ``approach``, ``icl``, ``dock``)."""

    def __init__(self, publish: Publish, clock: Clock) -> None:
        self._publish = publish
        self._clock = clock
        self._ids = itertools.count(1)
        self.pending: Request | None = None
        self.stale_responses = 0
        self.face_stream = False
        self.last_approach_at = -math.inf  # project-clock time of the last approach sent

    def goto(self, waypoint: str, poi: Poi) -> Request:
        now = self._clock.now()
        goal = Pose(now, "map", poi.x, poi.y, poi.z, poi.w)
        self._publish("goto", goal)
        return self._replace(Request(next(self._ids), "goto", waypoint, now, goal))

    def approach(self, person_id: int) -> Request:
        self._publish("approach", person_id)
        self.last_approach_at = now = self._clock.now()
        return self._replace(Request(next(self._ids), "approach", str(person_id), now,
                                     person_id))

    def resend_pending(self) -> Request | None:
        """Publish the pending goal or approach again (after a reconnect its answer may
        have been lost while the link was down). The request keeps waiting as before."""
        request = self.pending
        if request is not None and request.value is not None:
            self._publish(request.kind, request.value)  # the kind is the output role
            log.info("re-sent %s %s after a reconnect", request.kind, request.target)
        return request

    def _replace(self, request: Request) -> Request:
        self.pending = request
        return request

    def cancel(self, request: Request | None) -> None:
        """Stop waiting for ``request``; a later response to it is stale."""
        if request is not None and self.pending is request:
            self.pending = None

    def on_response(self, code: int, at: float) -> Request | None:
        """Apply one ``/FROG_response`` code; returns the request it answered, if any."""
        request = self.pending
        if request is None:
            self.stale_responses += 1
            log.debug("ignored /FROG_response %d: nothing pending", code)
            return None
        request.code, request.answered_at = code, at
        if code in TERMINAL:
            self.pending = None
        return request

    def dock(self, action: str) -> None:
        self._publish("dock", action)

    def icl(self, on: bool) -> None:
        self.face_stream = on
        self._publish("icl", "start" if on else "stop")
