"""The wire table: every ROS topic and front-end message the executive uses (CONTRACT).

One entry per input or output. Everything else derives from it: the executive's
subscriptions and advertisements, the decoders (each entry's ROS type is a
:class:`~frog_bt.rosbridge.msgs.RosType`, whose msgspec Struct also encodes for
the simulator and gives the recording's JSON schema), the inputs cache and the
blackboard keys the snapshot writes before each tick, whether a message calls
for a tick at once, and the inputs telemetry shows.

Adding an input is one :class:`Input` here (and a RosType, if the type is new)
plus the leaves that read its key: see ``docs/ARCHITECTURE.md``.

Topic names are configuration (``config/site.yaml`` ``topics:`` may rename them
by role); types and meanings are not. The front end's half of the table is the
message classes of :mod:`frog_bt.frontend.messages` (:data:`COMMANDS`,
:data:`EVENTS`): each class is one datagram type and its fields.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from frog_bt.frontend.messages import COMMANDS, EVENTS
from frog_bt.rosbridge import msgs
from frog_bt.rosbridge.msgs import RosType

__all__ = ["CLOCK", "COMMANDS", "EVENTS", "INPUTS", "OUTPUTS", "Input", "Keep", "Topic"]


class Keep(enum.Enum):
    """How an input reaches the blackboard, written once before each tick."""

    LATEST = "latest"  # the last message as a Reading(value, at), or None before any
    SAMPLES = "samples"  # the items of every message since the last tick: ((at, item), ...)
    QUEUE = "queue"  # every message since the last tick, in order: ((value, at), ...)


@dataclass(frozen=True, slots=True)
class Topic:
    name: str  # the default topic name
    codec: RosType[Any]

    @property
    def type(self) -> str:
        """The ROS type name (``geometry_msgs/PoseStamped``)."""
        return self.codec.name


@dataclass(frozen=True, slots=True)
class Input(Topic):
    key: str  # the blackboard key the snapshot writes
    keep: Keep = Keep.LATEST
    tick: bool = True  # a message calls for a tick at once (else the periodic tick covers it)
    items: Callable[[Any], Iterable[Any]] | None = None  # Keep.SAMPLES: a message's items
    limit: int = 10_000  # Keep.SAMPLES/QUEUE: most kept between ticks (a stalled tick)


# role -> input; roles are what the code and site.yaml refer to.
INPUTS: dict[str, Input] = {
    "pose": Input("/FROG_pose", msgs.POSE, "/pose", tick=False),
    "response": Input("/FROG_response", msgs.INT32, "/responses", Keep.QUEUE),
    "docking_state": Input("/docking/state", msgs.STRING, "/docking"),
    "diagnostic": Input("/diagnostic", msgs.DIAGNOSTICS, "/diagnostics"),
    "persons": Input("/UvA_PersonDetectionAndPose", msgs.PERSONS, "/persons"),
    "faces": Input("/ICL_FaceDataStream", msgs.FACES, "/faces", Keep.SAMPLES, tick=False,
                   items=lambda data: data.faces),
    "people": Input("/PeopleUPO", msgs.PEOPLE, "/people", tick=False),
}
CLOCK = Topic("/clock", msgs.CLOCK)  # sim time only; sets the clock, not the blackboard
OUTPUTS: dict[str, Topic] = {
    "goto": Topic("/GotoWayPoint", msgs.POSE),
    "approach": Topic("/ApproachPeopleFar", msgs.INT32),
    "icl": Topic("/ICL_command", msgs.STRING),
    "dock": Topic("/docking/dock", msgs.STRING),
}

# /FROG_response codes
ACTIVE, SUCCEEDED, FAILED, ABORTED = 1, 2, 3, 4
DOCKING_STATES = ("docked", "undocking", "undocked", "docking", "failed")

DEFAULT_ROSBRIDGE_URL = "ws://127.0.0.1:9090"
DEFAULT_FRONTEND = ("127.0.0.1", 5005)  # where the front end listens
DEFAULT_LISTEN = ("127.0.0.1", 5006)  # where the executive listens
