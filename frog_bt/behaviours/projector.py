"""Projector prewarm (seed: "POI3"): warm on arrival, never left on.

The projector needs about 20 s to warm up. On the way to a projector stop it is
switched on when the estimated time to arrival (remaining distance over the
recent speed) falls below the warm-up time, or on entering a radius of the
stop, whichever comes first; it is switched off when the stop's scope ends —
after its content, or when the tour is aborted or interrupted.
"""

from __future__ import annotations

import itertools
import math
from collections import deque

from frog_bt.behaviours.navigation import PoiParams
from frog_bt.behaviours.registry import register_decorator
from frog_bt.model import keys
from frog_bt.model.frontend import Projector as ProjectorCommand
from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import Status
from frog_bt.tree.world import Channel, World


def recent_speed(history: deque[tuple[float, float, float]]) -> float:
    """Path length over elapsed time of ``(t, x, y)`` samples; 0 with under 1 s of them."""
    if len(history) < 2 or history[-1][0] - history[0][0] < 1.0:
        return 0.0
    path = sum(math.hypot(b[1] - a[1], b[2] - a[2]) for a, b in itertools.pairwise(history))
    return path / (history[-1][0] - history[0][0])


@register_decorator
class Projector(FrogDecorator):
    """Projector on ahead of arrival at ``poi``, off when this scope ends.

    Reads ``/pose``, ``/now`` and, optionally, ``/waypoint`` (the variant being
    driven to). Sends ``projector`` on once ETA < ``projector.warmup`` +
    ``projector.margin`` or the
    robot is within ``projector.radius``; sends off when the scope ends, if on.
    Returns the child's status.
    """

    class Params(PoiParams):
        pass

    params: Params
    reads = (keys.POSE, keys.NOW)
    optional_reads = (keys.WAYPOINT,)
    world = World(
        inputs=(Channel.POSE,),
        state=("_on", "history"),
        copy=("history",),
        passes=True,
        key=lambda n: None,
        ignores=(keys.WAYPOINT.name,),
        why="the arrival estimate needs the robot's speed over seconds, which verify leaves "
        "out: the projector goes on within projector.radius of the stop. Whether it is on "
        "changes only what it sends, which no node or property reads",
    )

    def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        super().__init__(*args, **kwargs)
        self._on = False

    def initialise(self) -> None:
        self.history: deque[tuple[float, float, float]] = deque()

    def update(self) -> Status:
        if not self._on:
            self._consider()
        return self.decorated.status

    def _consider(self) -> None:
        pose = self.get(keys.POSE)
        target = self.ctx.site.pois.get(self.get(keys.WAYPOINT) or self.params.poi)
        if pose is None or target is None:
            return
        if pose.age(self.need(keys.NOW)) > self.ctx.site.safety.pose_max_age:
            self.feedback_message = "pose stale: no arrival estimate"
            return
        cfg = self.ctx.site.projector
        x, y = pose.value.x, pose.value.y
        if not self.history or pose.at > self.history[-1][0]:
            self.history.append((pose.at, x, y))
        while self.history and self.history[0][0] < pose.at - cfg.speed_window:
            self.history.popleft()
        distance = math.hypot(target.x - x, target.y - y)
        speed = recent_speed(self.history)
        eta = distance / speed if speed > 0.05 else math.inf
        if eta < cfg.warmup + cfg.margin or distance <= cfg.radius:
            self._on = True
            self.ctx.send(ProjectorCommand(True))
            why = f"ETA {eta:.0f} s" if distance > cfg.radius else f"{distance:.0f} m away"
            self.ctx.note(f"projector on: {why} to {self.params.poi}")

    def terminate(self, new_status: Status) -> None:
        if self._on:
            self._on = False
            self.ctx.send(ProjectorCommand(False))
            self.ctx.note(f"projector off: {self.params.poi} done")
