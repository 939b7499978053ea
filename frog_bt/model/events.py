"""What the executive tells its observers: one typed event at a time.

Every observer (recording, rotation, summary, status line, console, telemetry, webhooks)
hears the executive through one call, ``on_event(event)``, where ``event`` is one of the
Structs of :data:`Event`. This union is the one list of what the executive says; the
recorder writes these same values, and :mod:`frog_bt.recordings.reader` reads them back.

==================  =========================================================
event               when
==================  =========================================================
:class:`RobotInput`     a message arrived on a subscribed robot topic
:class:`RobotCommand`   a command went to the robot (goal, approach, face stream, dock)
:class:`FrontendIn`     a new front-end event arrived (duplicates and acks are not new)
:class:`FrontendOut`    a command went to the front end
:class:`Datagram`       a UDP datagram crossed the front-end link (acks, resends included)
:class:`Ticked`         the tree ticked once
:class:`Blamed`         right after a command: the node that sent it, and what it read
:class:`OperatorDone`   an operator command was applied or refused
:class:`LinksChanged`   a link changed state
:class:`AlertChanged`   an alert was raised, cleared or acknowledged
:class:`Doubted`        a robot's answer was not believed (stale, or not what the world shows)
:class:`Faulted`        the executive's own code failed at one place (caught, counted)
==================  =========================================================

Times are project-clock seconds. Values are the wire Structs' values (what the leaves
see); ``RobotInput.raw`` and ``RobotCommand.msg`` are the rosbridge ``msg`` as it crossed
the wire, for the recorder.

Each event is a tagged Struct (tag field ``type``, tag its class name). The recorder
writes the executive's own events as themselves, one per message of frog-bt's channels
(:data:`Recorded`, :mod:`frog_bt.model.channels`); what crossed a wire it writes as it
crossed (CONTRACT §6: the rosbridge ``msg``, the datagram's bytes), and the reader
(:mod:`frog_bt.recordings.reader`) gives back the same events from both.
"""

from __future__ import annotations

from typing import Any, Literal

import msgspec

from frog_bt.model.alert import Alert
from frog_bt.model.frontend import FrontendMessage
from frog_bt.model.goals import Goal
from frog_bt.model.links import Links

__all__ = [
    "AlertChanged",
    "Blamed",
    "Datagram",
    "Doubted",
    "Event",
    "Faulted",
    "FrontendIn",
    "FrontendOut",
    "LinksChanged",
    "OperatorDone",
    "Recorded",
    "RobotCommand",
    "RobotInput",
    "Ticked",
]

TickStatus = Literal["INVALID", "RUNNING", "SUCCESS", "FAILURE"]


class RobotInput(msgspec.Struct, frozen=True, tag=True):
    """A message on a subscribed robot topic: its decoded value (None for a topic the
    tree does not read, such as ``/clock``) and, live, the ``msg`` as received."""

    t: float
    topic: str
    value: object = None
    raw: msgspec.Raw | None = None


class RobotCommand(msgspec.Struct, frozen=True, tag=True):
    """A command to the robot: its output role and topic, the typed value, the ``msg``
    sent, and the goal it carries (goto, approach; None for the others)."""

    t: float
    role: str
    topic: str
    value: object
    msg: dict[str, Any]
    goal: Goal | None = None


class FrontendIn(msgspec.Struct, frozen=True, tag=True):
    """A new front-end event, decoded."""

    t: float
    message: FrontendMessage


class FrontendOut(msgspec.Struct, frozen=True, tag=True):
    """A command to the front end (sent once here; the link resends it until acked)."""

    t: float
    message: FrontendMessage


class Datagram(msgspec.Struct, frozen=True, tag=True):
    """One UDP datagram in from the front-end host, or out to the front end."""

    t: float
    direction: Literal["in", "out"]
    data: bytes


class Ticked(msgspec.Struct, frozen=True, tag=True):
    """The tree ticked: the tick's number (from 1) and the root's status after it."""

    t: float
    tick: int
    status: TickStatus


class Blamed(msgspec.Struct, frozen=True, tag=True):
    """Right after a command: the tree node that sent it and the values it read."""

    t: float
    channel: str  # ROS topic or front-end message type
    node: str
    reads: dict[str, str] = {}


class OperatorDone(msgspec.Struct, frozen=True, tag=True):
    """An operator command and its answer; ``tick`` is the tick it came before."""

    t: float
    tick: int
    command: str
    ok: bool
    text: str
    id: str = ""  # ack_alert: the alert
    by: str = ""  # who sent it: console, ctl, link (empty when unknown)


class LinksChanged(msgspec.Struct, frozen=True, tag=True):
    """The links' states now, after one of them changed."""

    t: float
    links: Links


class AlertChanged(msgspec.Struct, frozen=True, tag=True):
    """An alert was raised, cleared or acknowledged."""

    t: float
    alert: Alert


class Doubted(msgspec.Struct, frozen=True, tag=True):
    """A ``/FROG_response`` the executive did not act on: ``code``, the goal pending when
    it came (``goal``: its target, e.g. ``SHOP``), what it is taken to answer instead
    (``answers``: an earlier goal's target, or ""), and ``why`` in domain terms
    ("arrival at POI2 heard after the drive to SHOP: ignored")."""

    t: float
    code: int
    goal: str
    why: str
    answers: str = ""


class Faulted(msgspec.Struct, frozen=True, tag=True):
    """The executive's own code failed at ``where`` (a node, an input, an observer) while
    doing ``what``; the error (inert text) and how often that place has failed so far."""

    t: float
    where: str
    what: str
    error: str
    count: int


Event = (
    RobotInput
    | RobotCommand
    | FrontendIn
    | FrontendOut
    | Datagram
    | Ticked
    | Blamed
    | OperatorDone
    | LinksChanged
    | AlertChanged
    | Doubted
    | Faulted
)

Recorded = Ticked | Blamed | OperatorDone | AlertChanged | LinksChanged | Doubted | Faulted
"""The events frog-bt's own recording channels hold, each as itself (one tagged union)."""
