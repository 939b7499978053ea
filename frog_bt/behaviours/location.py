"""Location awareness (seed: "Location based"): volume zones, follow-me, special content.

A pose older than ``safety.pose_max_age`` is not acted on: the location
features pause (and say so) until poses flow again.

* :class:`LocationAware` — around the whole tour: ``volume`` for the zone the
  robot is in (shop 50%, Tapestry and Vault Rooms 80%, elsewhere the default),
  sent on entering a zone, with hysteresis.
* :class:`GuidedDrive` — around a drive with a visitor following: ``follow_me``
  on while driving, off on entering the target's arrival range; and each
  nearby facility (toilets, shop, bar) announced once per tour
  (``special_content``) when the robot passes within its range.
"""

from __future__ import annotations

import math

from frog_bt.behaviours.navigation import PoiParams
from frog_bt.behaviours.registry import register_decorator
from frog_bt.config import ZoneShape
from frog_bt.maths.zones import Membership, Shape
from frog_bt.model import keys
from frog_bt.model.frontend import FollowMe, SpecialContent, Volume
from frog_bt.model.key import Reading
from frog_bt.model.ros import Pose
from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import Status
from frog_bt.tree.world import Channel, World


def fresh_pose(node: FrogDecorator) -> Reading[Pose] | None:
    """``/pose`` when fresher than ``safety.pose_max_age``; else None, and the node says so."""
    pose = node.get(keys.POSE)
    if pose is None or pose.age(node.need(keys.NOW)) > node.ctx.site.safety.pose_max_age:
        node.feedback_message = "pose stale or missing: location features paused"
        return None
    node.feedback_message = ""
    return pose


def shape_of(zone: ZoneShape) -> Shape:
    if zone.circle is not None:
        return Shape(center=(zone.circle.x, zone.circle.y), radius=zone.circle.r)
    return Shape(points=tuple(zone.polygon or ()))


@register_decorator
class LocationAware(FrogDecorator):
    """Audio volume by zone while the child runs.

    Reads ``/pose``. Sends ``volume`` whenever the zone the robot is in changes
    (and once at the start), with ``zones.volume.hysteresis`` metres of
    hysteresis at the borders. Returns the child's status.
    """

    reads = (keys.POSE, keys.NOW)
    world = World(
        inputs=(Channel.POSE,),
        state=("zones", "membership", "percent"),
        copy=("membership",),
        passes=True,
        key=lambda n: None,
        why="the zone follows from where the robot is (a waypoint); the volume it sends "
        "is all its state changes, and no node or property reads it",
    )

    def initialise(self) -> None:
        cfg = self.ctx.site.zones.volume
        self.zones = cfg.zones
        self.membership = Membership([shape_of(z) for z in cfg.zones], cfg.hysteresis)
        self.percent: int | None = None

    def update(self) -> Status:
        pose = fresh_pose(self)
        if pose is not None:
            index = self.membership.update((pose.value.x, pose.value.y))
            zone = self.zones[index] if index is not None else None
            percent = zone.percent if zone else self.ctx.site.zones.volume.default
            if percent != self.percent:
                self.percent = percent
                self.ctx.send(Volume(percent))
                self.ctx.note(f"volume {percent}%: {zone.name if zone else 'outdoors'}")
        return self.decorated.status


@register_decorator
class GuidedDrive(FrogDecorator):
    """``follow_me`` and special content while driving a visitor to ``poi``.

    Sends ``follow_me`` on when entered and off on entering the arrival range
    of the target waypoint (``zones.arrival``) or when left. Sends
    ``special_content`` for each spot of ``zones.special`` the robot passes
    within, once per tour. Reads ``/pose`` and, optionally, ``/waypoint`` and
    ``/special_done``; writes ``/special_done``. Returns the child's status.
    """

    Params = PoiParams
    params: PoiParams
    reads = (keys.POSE, keys.NOW)
    optional_reads = (keys.WAYPOINT, keys.SPECIAL_DONE)
    writes = (keys.SPECIAL_DONE,)
    world = World(
        inputs=(Channel.POSE,),
        state=("_on", "spots"),
        passes=True,
        key=lambda n: None,
        ignores=(keys.SPECIAL_DONE.name, keys.WAYPOINT.name),
        why="follow_me and special content follow from where the robot is (a waypoint); "
        "what it sends is all its state and /special_done change, and no node or "
        "property reads that",
    )

    def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
        super().__init__(*args, **kwargs)
        self._on = False

    def initialise(self) -> None:
        self.ctx.send(FollowMe(True))
        self._on = True
        self.spots = [(s.spot, shape_of(s)) for s in self.ctx.site.zones.special]

    def update(self) -> Status:
        pose = fresh_pose(self)
        if pose is not None:
            p = (pose.value.x, pose.value.y)
            site = self.ctx.site
            target = site.pois.get(self.get(keys.WAYPOINT) or self.params.poi)
            radius = site.zones.arrival_radius(self.params.poi)
            if (
                self._on
                and target is not None
                and math.hypot(p[0] - target.x, p[1] - target.y) <= radius
            ):
                self._follow_off(f"within {radius:g} m of {self.params.poi}")
            done: frozenset[str] = self.get(keys.SPECIAL_DONE) or frozenset()
            for spot, shape in self.spots:
                if spot not in done and shape.contains(p):
                    done = done | {spot}
                    self.set(keys.SPECIAL_DONE, done)
                    self.ctx.send(SpecialContent(spot))
                    self.ctx.note(f"special content: {spot} nearby")
        return self.decorated.status

    def _follow_off(self, why: str) -> None:
        self._on = False
        self.ctx.send(FollowMe(False))
        self.ctx.note(f"follow_me off: {why}")

    def terminate(self, new_status: Status) -> None:
        if self._on:
            self._follow_off("drive ended")
