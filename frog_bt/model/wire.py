"""The wire table: every ROS topic and front-end message the executive uses (CONTRACT).

One entry per input or output. Everything else derives from it: the executive's
subscriptions and advertisements, the decoders (each entry's ROS type is a
:class:`~frog_bt.model.ros.RosType`, whose msgspec Struct also encodes for
the simulator and gives the recording's JSON schema), the inputs cache and the
blackboard keys the snapshot writes before each tick, whether a message calls
for a tick at once, and the inputs telemetry shows.

Adding an input is one :class:`Input` here (and a RosType, if the type is new)
plus the leaves that read its key: see ``docs/ARCHITECTURE.md``.

Topic names are configuration (``config/site.yaml`` ``topics:`` may rename them
by role); types and meanings are not. The front end's half of the table is the
message classes of :mod:`frog_bt.model.frontend` (:data:`COMMANDS`,
:data:`EVENTS`): each class is one datagram type and its fields.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, TypeVar

from frog_bt.model import ros as msgs
from frog_bt.model.frontend import COMMANDS, EVENTS
from frog_bt.model.key import Key, Reading, Scope, Source
from frog_bt.model.ros import (
    Diagnostics,
    Face,
    PersonDetections,
    Pose,
    RosType,
    TrackedPeople,
)

__all__ = ["CLOCK", "COMMANDS", "EVENTS", "INPUTS", "OUTPUTS", "Input", "Keep", "Response", "Topic"]

T = TypeVar("T")


class Keep(enum.Enum):
    """How an input reaches the blackboard, written once before each tick."""

    LATEST = "latest"  # the last message as a Reading(value, at), or None before any
    SAMPLES = "samples"  # the items of every message since the last tick: ((at, item), ...)
    QUEUE = "queue"  # every message since the last tick, in order: ((value, at, poses), ...)


@dataclass(frozen=True, slots=True)
class Topic:
    name: str  # the default topic name
    codec: RosType[Any]

    @property
    def type(self) -> str:
        """The ROS type name (``geometry_msgs/PoseStamped``)."""
        return self.codec.name


def input_key(name: str, type_: type[T], doc: str) -> Key[T]:
    """The key an input's snapshot writes: ``Reading[T]`` for :attr:`Keep.LATEST`, a
    tuple for the others; kept for the executive's life."""
    return Key(name, type_, Source.INPUT, Scope.PROCESS, doc)


@dataclass(frozen=True, slots=True)
class Input(Topic):
    key: Key[Any]  # the blackboard key the snapshot writes
    keep: Keep = Keep.LATEST
    tick: bool = True  # a message calls for a tick at once (else the periodic tick covers it)
    items: Callable[[Any], Iterable[Any]] | None = None  # Keep.SAMPLES: a message's items
    limit: int = 10_000  # Keep.SAMPLES/QUEUE: most kept between ticks (a stalled tick)


# The inputs' keys: a Reading (value, time received), or None before any message.
POSE = input_key("/pose", Reading[Pose], "the robot's pose in the map frame")
RESPONSES = input_key(
    "/responses",
    tuple[tuple[int, float, int], ...],
    "/FROG_response codes received since the last tick: (code, t, poses received before it)",
)
DOCKING = input_key(
    "/docking", Reading[str], "the docking state (a DockingState word: docked, undocking, ...)"
)
DIAGNOSTICS = input_key(
    "/diagnostics", Reading[Diagnostics], "battery level and electronics faults"
)
PERSONS = input_key(
    "/persons", Reading[PersonDetections], "people the camera sees, with their orientation"
)
FACES = input_key(
    "/faces", tuple[tuple[float, Face], ...], "face samples received since the last tick: (t, face)"
)
PEOPLE = input_key("/people", Reading[TrackedPeople], "people the laser tracks")

# role -> input; roles are what the code and site.yaml refer to.
INPUTS: dict[str, Input] = {
    "pose": Input("/FROG_pose", msgs.POSE, POSE, tick=False),
    "response": Input("/FROG_response", msgs.INT32, RESPONSES, Keep.QUEUE),
    "docking_state": Input("/docking/state", msgs.STRING, DOCKING),
    "diagnostic": Input("/diagnostic", msgs.DIAGNOSTICS, DIAGNOSTICS),
    "persons": Input("/UvA_PersonDetectionAndPose", msgs.PERSONS, PERSONS),
    "faces": Input(
        "/ICL_FaceDataStream",
        msgs.FACES,
        FACES,
        Keep.SAMPLES,
        tick=False,
        items=lambda data: data.faces,
    ),
    "people": Input("/PeopleUPO", msgs.PEOPLE, PEOPLE, tick=False),
}
CLOCK = Topic("/clock", msgs.CLOCK)  # sim time only; sets the clock, not the blackboard
OUTPUTS: dict[str, Topic] = {
    "goto": Topic("/GotoWayPoint", msgs.POSE),
    "approach": Topic("/ApproachPeopleFar", msgs.INT32),
    "icl": Topic("/ICL_command", msgs.STRING),
    "dock": Topic("/docking/dock", msgs.STRING),
}


class Response(enum.IntEnum):
    """``/FROG_response`` codes (CONTRACT §1); ``word`` is the name people read."""

    ACTIVE = 1
    SUCCEEDED = 2
    FAILED = 3
    ABORTED = 4

    @property
    def word(self) -> str:
        return self.name.lower()

    @property
    def terminal(self) -> bool:
        return self is not Response.ACTIVE

    @classmethod
    def of(cls, code: int) -> Response | None:
        """The response a code means; None for a code the contract does not know."""
        return cls._value2member_map_.get(code)  # type: ignore[return-value]


ACTIVE, SUCCEEDED, FAILED, ABORTED = Response

DEFAULT_ROSBRIDGE_URL = "ws://127.0.0.1:9090"
DEFAULT_FRONTEND = ("127.0.0.1", 5005)  # where the front end listens
DEFAULT_LISTEN = ("127.0.0.1", 5006)  # where the executive listens
