"""frog-bt's own recording channels: what each holds, declared once.

The recorder (:mod:`frog_bt.live.recording`) writes them and the one reader of recordings
(:mod:`frog_bt.recordings.reader`) reads them back; each channel's JSON Schema in the MCAP
file is derived from the same Struct (:func:`schemas`). A message that does not decode
is a :class:`~frog_bt.errors.DecodeError` naming the field: replay counts and reports it,
never drops it silently.

The channels that tell what happened hold the executive's own events
(:mod:`frog_bt.model.events`), each as itself: one tagged msgspec union
(:data:`~frog_bt.model.events.Recorded`, tag ``type``: the event's class name), encoded
once by :func:`encode` and decoded in one pass by :func:`decode_event`. Three more hold
what a file carries besides (the tree, a primer, what a restarted executive took up).

=====================  ===========================  =======================================
channel                schema name                  one message per
=====================  ===========================  =======================================
``/frog_bt/tick``      ``frog_bt/Ticked``           tick of the tree
``/frog_bt/blame``     ``frog_bt/Blamed``           command, right after it: who sent it
``/frog_bt/operator``  ``frog_bt/OperatorDone``     operator command, with its answer
``/frog_bt/alert``     ``frog_bt/AlertChanged``     alert raised, cleared or acknowledged
``/frog_bt/doubt``     ``frog_bt/Doubted``          robot answer not believed (stale, or off)
``/frog_bt/fault``     ``frog_bt/Faulted``          failure of the executive's own code, caught
``/frog_bt/links``     ``frog_bt/LinksChanged``     change of a link's state (the alerts read
                                                    them)
``/frog_bt/tree``      ``frog_bt/Tree``             file: the tree that ran (BT.CPP v4 XML)
``/frog_bt/primer``    ``frog_bt/Primer``           rotated file: what it carries from before
``/frog_bt/restored``  ``frog_bt/Restored``         file of a started executive: what it took
                                                    up from before it (checkpoint, staff's
                                                    decisions)
=====================  ===========================  =======================================

Recordings made before the events were recorded as themselves hold other shapes on the
event channels (schema names ``frog_bt/Tick``, ``Blame``, ``Operator``, ``Alert``,
``Doubt``, ``Fault``, ``Links``): the reader reads them too
(:mod:`frog_bt.recordings.legacy`). The channels of CONTRACT §6 (one per ROS topic,
``/frontend/in``, ``/frontend/out``) are not ours to shape: they hold what crossed the
wire.
"""

from __future__ import annotations

import math
from typing import Any, cast

import msgspec

from frog_bt.codec import decoder
from frog_bt.model.alert import Alert
from frog_bt.model.events import (
    AlertChanged,
    Blamed,
    Doubted,
    Faulted,
    LinksChanged,
    OperatorDone,
    Recorded,
    Ticked,
)
from frog_bt.model.frontend import COMMANDS, EVENTS
from frog_bt.model.ros import ROS_TYPES

__all__ = ["Alert"]  # (also what Carried holds; its home is frog_bt.model.alert)

FRONTEND_IN = "/frontend/in"
FRONTEND_OUT = "/frontend/out"
DATAGRAM_TYPE = "frog_bt/FrontendDatagram"
TICK = "/frog_bt/tick"
BLAME = "/frog_bt/blame"  # the tree node that sent each command, right after it
TREE = "/frog_bt/tree"  # the tree that ran, as BehaviorTree.CPP v4 XML, once at the start
PRIMER = "/frog_bt/primer"  # what a rotated file carries from before it
SITE_METADATA = "frog_bt_site"  # MCAP metadata in every file: config_sha256, the site config
OPERATOR = "/frog_bt/operator"  # each operator command and its answer
ALERT = "/frog_bt/alert"  # each alert's changes
DOUBT = "/frog_bt/doubt"  # each robot answer not believed, and why
FAULT = "/frog_bt/fault"  # each failure of the executive's own code, caught and counted
LINKS = "/frog_bt/links"  # the links' states, at each change
RESTORED = "/frog_bt/restored"  # what a started executive took up from before it


class Tree(msgspec.Struct, frozen=True):
    format: str
    file: str
    xml: str  # the tree (Groot2 opens it)


class PrimerInput(msgspec.Struct, frozen=True):
    topic: str
    t: float
    msg: msgspec.Raw  # the input's latest message, as received


class Primer(msgspec.Struct, frozen=True):
    inputs: list[PrimerInput] = []
    frontend_ready: bool = False
    frontend_in: list[str] = []  # recent datagrams in: their resends stay duplicates
    frontend_out_seqs: list[int] = []  # recent seqs out: resends are not new commands
    staff: Carried | None = None  # beside the tree: the staff's decisions, the alert book


class CarriedIncident(msgspec.Struct, frozen=True):
    at: float
    kind: str  # an IncidentKind value
    text: str
    subject: str = ""


class Carried(msgspec.Struct, frozen=True):
    """What the executive carries beside the tree into a rotated file (in its primer):
    the staff's standing decisions and the alert book (``active``: the alerts raised and
    not cleared, as last told; ``shown``: those not yet acknowledged, raised or cleared;
    ``told_at``: when each active one was last told, for its escalation), and what the
    alert conditions read of the latest tour (its incidents: the stops given up; whether
    a pause ended it)."""

    in_service: bool = True
    paused: bool = False
    active: list[Alert] = []
    shown: list[Alert] = []
    told_at: dict[str, float] = {}
    tour_incidents: list[CarriedIncident] = []
    pause_ran_out: bool = False


class RestoredHelp(msgspec.Struct, frozen=True):
    about: str  # a HelpAbout value: undock, dock, home, fault, crashed
    since: float
    detail: str = ""  # crashed: why


class Restored(msgspec.Struct, frozen=True):
    """What an executive took up at start-up from the one before it (a restart): the
    resume point of its checkpoint (``done``: the checkpoints done, in order; empty: none;
    ``visitor``; ``written``: wall time) and what staff had decided (out of service, a
    pause, the help the robot waited for, the alerts acknowledged). Replay starts from
    the same."""

    done: list[str] = []
    visitor: int | None = None
    written: float = 0.0
    in_service: bool = True
    paused: bool = False
    help: RestoredHelp | None = None
    acknowledged: list[str] = []


EVENT_CHANNELS: dict[type[Recorded], str] = {
    Ticked: TICK,
    Blamed: BLAME,
    OperatorDone: OPERATOR,
    AlertChanged: ALERT,
    Doubted: DOUBT,
    Faulted: FAULT,
    LinksChanged: LINKS,
}
"""The channel each recorded event is written on."""

FILE_TYPES: dict[str, type[msgspec.Struct]] = {TREE: Tree, PRIMER: Primer, RESTORED: Restored}
"""The channels that hold what a file carries besides its events."""

TYPES: dict[str, tuple[str, Any]] = {
    **{channel: (f"frog_bt/{cls.__name__}", cls) for cls, channel in EVENT_CHANNELS.items()},
    **{channel: (f"frog_bt/{cls.__name__}", cls) for channel, cls in FILE_TYPES.items()},
}
"""Every channel of ours (but the datagrams'): its schema name and its Struct."""

_ENCODER = msgspec.json.Encoder()
_DECODERS = {channel: decoder(struct) for channel, struct in FILE_TYPES.items()}
# a union is a type form, not a ``type[T]`` (no TypeForm before PEP 747): what it decodes
_EVENT = decoder(cast("type[Recorded]", Recorded))


def encode(message: msgspec.Struct) -> bytes:
    """A message of one of our channels, as JSON: an event (with its tag), a file's Struct."""
    return _ENCODER.encode(message)


def decode(channel: str, data: bytes) -> Any:
    """The message of ``channel`` in ``data`` (an event's channel: the event, whichever
    its tag names); DecodeError with the field's path."""
    decode_file = _DECODERS.get(channel)
    return _EVENT(data) if decode_file is None else decode_file(data)


def decode_event(data: bytes) -> Recorded:
    """One recorded event, in one pass over the tagged union; DecodeError naming the
    field (or the unknown tag)."""
    return _EVENT(data)


def _inline(node: Any, defs: dict[str, Any]) -> Any:
    if isinstance(node, dict):
        if "$ref" in node:
            return _inline(defs[node["$ref"].rsplit("/", 1)[1]], defs)
        return {k: _inline(v, defs) for k, v in node.items() if k != "$defs"}
    if isinstance(node, list):
        return [_inline(v, defs) for v in node]
    return node


def struct_schema(types: Any, title: str) -> dict[str, Any]:
    """The JSON schema of a Struct type (or a union of them), refs inlined: one
    self-contained schema per channel."""
    schema = msgspec.json.decode(msgspec.json.encode(msgspec.json.schema(types)))
    return {**_inline(schema, schema.get("$defs", {})), "title": title}


def schemas() -> dict[str, dict[str, Any]]:
    """Schema name -> JSON Schema, for every channel of this module."""
    return {name: struct_schema(struct, name) for name, struct in TYPES.values()}


# ------------------------------------------------------------------ JSON Schemas
# The datagram channels' and ours, and any ROS type's from its Struct.


def _datagram_schema() -> dict[str, Any]:
    """Every front-end message's fields in one object: a datagram is one of them."""
    props: dict[str, Any] = {
        "type": {"type": "string", "description": "command, event or ack (CONTRACT §2)"},
        "seq": {"type": "integer", "minimum": 0},
    }
    for cls in (*COMMANDS.values(), *EVENTS.values()):
        props.update(struct_schema(cls, cls.type).get("properties", {}))
    return {
        "type": "object",
        "title": DATAGRAM_TYPE,
        "properties": props,
        "required": ["type", "seq"],
    }


OWN_SCHEMAS: dict[str, dict[str, Any]] = {DATAGRAM_TYPE: _datagram_schema(), **schemas()}


def schema_for(type_: str) -> dict[str, Any]:
    """The JSON Schema of a channel's type: a ROS type's from its Struct (whatever the
    wire table holds now), or one of ours."""
    codec = ROS_TYPES.get(type_)
    if codec is not None:
        return struct_schema(codec.wire, type_)
    return OWN_SCHEMAS.get(type_, {"type": "object"})


OWN_TYPES = {
    FRONTEND_IN: DATAGRAM_TYPE,
    FRONTEND_OUT: DATAGRAM_TYPE,
    **{channel: name for channel, (name, _) in TYPES.items()},
}


def to_ns(t: float) -> int:
    """Clock seconds to integer nanoseconds; :func:`from_ns` gives ``t`` back exactly for
    any epoch time (float spacing there is far above a nanosecond)."""
    whole = math.floor(t)
    return whole * 1_000_000_000 + round((t - whole) * 1e9)


def from_ns(ns: int) -> float:
    """Integer nanoseconds to clock seconds (the float :func:`to_ns` was given)."""
    whole, frac = divmod(ns, 1_000_000_000)
    return whole + frac / 1e9
