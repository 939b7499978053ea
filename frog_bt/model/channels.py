"""frog-bt's own recording channels, each message declared once as a msgspec Struct.

The recorder (:mod:`frog_bt.live.recording`) writes them, replay
(:mod:`frog_bt.offline.replay`) reads them, and each channel's JSON Schema in the MCAP
file is derived from the same Struct (:func:`schemas`). A message that does not decode
is a :class:`~frog_bt.errors.DecodeError` naming the field: replay counts and reports it,
never drops it silently.

=====================  ======================  ============================================
channel                schema name             one message per
=====================  ======================  ============================================
``/frog_bt/tick``      ``frog_bt/Tick``        tick of the tree
``/frog_bt/blame``     ``frog_bt/Blame``       command, right after it: who sent it
``/frog_bt/tree``      ``frog_bt/Tree``        file: the tree that ran (BT.CPP v4 XML)
``/frog_bt/primer``    ``frog_bt/Primer``      rotated file: what it carries from before
``/frog_bt/operator``  ``frog_bt/Operator``    operator command, with its answer
``/frog_bt/alert``     ``frog_bt/Alert``       alert raised, cleared or acknowledged
``/frog_bt/doubt``     ``frog_bt/Doubt``       robot answer not believed (stale, or off)
``/frog_bt/fault``     ``frog_bt/Fault``       failure of the executive's own code, caught
``/frog_bt/links``     ``frog_bt/Links``       change of a link's state (the alerts read them)
``/frog_bt/restored``  ``frog_bt/Restored``    file of a started executive: what it took up
                                               from before it (checkpoint, staff's decisions)
=====================  ======================  ============================================
"""

from __future__ import annotations

import math
from typing import Any, Literal

import msgspec

from frog_bt.codec import decoder
from frog_bt.model.frontend import COMMANDS, EVENTS
from frog_bt.model.links import LinkStatus
from frog_bt.model.ros import ROS_TYPES

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


class Tick(msgspec.Struct, frozen=True):
    tick: int
    status: Literal["INVALID", "RUNNING", "SUCCESS", "FAILURE"]


class Blame(msgspec.Struct, frozen=True):
    channel: str  # ROS topic or front-end message type
    node: str  # the tree node that sent it, and where it is written
    reads: dict[str, str] = {}  # the blackboard values that node read, as short text


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


class Operator(msgspec.Struct, frozen=True):
    tick: int  # the tick it came before: replay applies it there
    command: str
    ok: bool
    text: str  # what it did, or why it was refused
    id: str = ""  # ack_alert: the alert
    by: str = ""  # who sent it: console, ctl, link (empty when unknown; added later)


class Alert(msgspec.Struct, frozen=True):
    """One alert change (``state``: raised, cleared = resolved, acknowledged by a person).

    The fields after ``since`` came later, each with a default, so older recordings still
    decode: ``severity`` in ROS diagnostics' levels (REP-107), ``key`` the stable
    deduplication key (``frog-bt:<robot>:<kind>[:<subject>]``), ``subject`` what it is
    about (a stop), ``answers`` the operator commands that apply, ``what`` and ``todo``
    the two halves of ``text`` (the sentence, what to do), ``repeat`` how many times it
    has been told again unacknowledged (escalation; 0: the first telling) and ``waited``
    the project-clock seconds since it was raised, at that repeat."""

    id: str
    kind: str
    text: str
    state: Literal["raised", "cleared", "acknowledged"]
    since: float
    severity: Literal["WARN", "ERROR"] = "WARN"
    key: str = ""
    subject: str = ""
    answers: tuple[str, ...] = ()
    what: str = ""
    todo: str = ""
    repeat: int = 0
    waited: float = 0.0

    @property
    def occurrence(self) -> str:
        """Which raise of this alert: its raise time as text (the same through escalation,
        clearing and acknowledgement; a later raise of the same alert has another)."""
        return f"{self.since:.6f}"


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


class Links(msgspec.Struct, frozen=True):
    """The links' states after one of them changed (the alerts ``rosbridge_down`` and
    ``frontend_silent`` read them; replay takes them from here)."""

    rosbridge: LinkStatus
    frontend: LinkStatus
    clock: LinkStatus


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


class Doubt(msgspec.Struct, frozen=True):
    code: int  # the /FROG_response code
    goal: str  # the goal pending when it came (its target)
    why: str  # in domain terms: "arrival at POI2 heard after the drive to SHOP: ignored"
    answers: str = ""  # the earlier goal it is taken to answer, if known


class Fault(msgspec.Struct, frozen=True):
    where: str  # the node, input or observer that failed
    what: str  # what it was doing
    error: str  # the error, inert text
    count: int  # failures at that place so far


TYPES: dict[str, tuple[str, type[msgspec.Struct]]] = {
    TICK: ("frog_bt/Tick", Tick),
    BLAME: ("frog_bt/Blame", Blame),
    TREE: ("frog_bt/Tree", Tree),
    PRIMER: ("frog_bt/Primer", Primer),
    OPERATOR: ("frog_bt/Operator", Operator),
    ALERT: ("frog_bt/Alert", Alert),
    DOUBT: ("frog_bt/Doubt", Doubt),
    FAULT: ("frog_bt/Fault", Fault),
    LINKS: ("frog_bt/Links", Links),
    RESTORED: ("frog_bt/Restored", Restored),
}

_ENCODER = msgspec.json.Encoder()
_DECODERS = {channel: decoder(struct) for channel, (_, struct) in TYPES.items()}


def encode(message: msgspec.Struct) -> bytes:
    return _ENCODER.encode(message)


def decode(channel: str, data: bytes) -> Any:
    """The message of ``channel`` in ``data``; DecodeError with the field's path."""
    return _DECODERS[channel](data)


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
