"""Every value a tour uses, declared once: name, type, who writes it, how long it lives.

Leaves name these objects in ``reads`` / ``optional_reads`` / ``writes`` and get typed
values back; the data-flow check, blame, telemetry, replay, ``frog-bt leaves``, the JSON
Schema and docs/TREES.md read the same declarations. The robot's inputs are declared
beside their topics in :mod:`frog_bt.model.wire` (adding an input is one entry there) and are
part of :data:`ALL` below.

Scopes (:class:`~frog_bt.model.key.Scope`): a tree node that starts a scope (each stop
of a ``foreach``, a node with ``scope:`` in a tree file) clears the keys of that scope and
of the narrower ones when it starts, so an optional read never sees another stop's or an
earlier visitor's value; the data-flow check refuses a required read that only an
earlier scope wrote.
"""

from __future__ import annotations

from typing import Any, TypeVar

from frog_bt.maths.engagement import Decision, Samples
from frog_bt.model.eventlog import EventLog
from frog_bt.model.goals import Goal
from frog_bt.model.help import Help, HelpAnswer
from frog_bt.model.key import Key, Reading, Scope, Source
from frog_bt.model.outcomes import AbortReason, Incident, TourState
from frog_bt.model.progress import Progress, Resume
from frog_bt.model.wire import (
    DIAGNOSTICS,
    DOCKING,
    FACES,
    INPUTS,
    PEOPLE,
    PERSONS,
    POSE,
    RESPONSES,
)

__all__ = [
    "ALL",
    "DIAGNOSTICS",
    "DOCKING",
    "FACES",
    "PEOPLE",
    "PERSONS",
    "POSE",
    "RESPONSES",
    "Key",
    "Reading",
    "Scope",
    "Source",
    "by_name",
]


def _key(
    name: str, type_: type[T], source: Source, scope: Scope, doc: str, lasting: bool = False
) -> Key[T]:
    return Key(name, type_, source, scope, doc, lasting)


T = TypeVar("T")
IN, L, E = Source.INPUT, Source.LEAF, Source.EXECUTIVE

# -- written before each tick, with the inputs
NOW = _key("/now", float, IN, Scope.PROCESS, "project-clock time of this tick (s)")
EVENTS = _key(
    "/events", EventLog, IN, Scope.PROCESS, "the front end's events, in order", lasting=True
)
FRONTEND_READY = _key(
    "/frontend_ready",
    bool,
    IN,
    Scope.PROCESS,
    "a frontend_idle arrived since the last tour started or ended",
    lasting=True,
)
GOAL = _key(
    "/goal",
    Goal,
    IN,
    Scope.PROCESS,
    "the newest goal or approach sent, with its latest /FROG_response",
)

# -- the tour's bookkeeping
TOUR_STATE = _key(
    "/tour_state", TourState, L, Scope.PROCESS, "the latest tour state sent", lasting=True
)
TOUR_REASON = _key(
    "/tour_reason", str, L, Scope.PROCESS, "and its reason (with aborted)", lasting=True
)
PROGRESS = _key(
    "/progress",
    Progress,
    L,
    Scope.PROCESS,
    "checkpoints done this tour (the executive saves each new value)",
    lasting=True,
)
RESUME = _key(
    "/resume",
    Resume,
    E,
    Scope.PROCESS,
    "what a tour resumed from a checkpoint skips (set at start-up)",
    lasting=True,
)
RESUMED = _key(
    "/resumed",
    str,
    L,
    Scope.PROCESS,
    "how the tour was resumed, in words (resuming the tour at POI4: ...)",
    lasting=True,
)
GAVE_UP = _key(
    "/gave_up", Incident, L, Scope.PROCESS, "why the tree gave up: the executive stops with it"
)
ABORT_REASON = _key(
    "/abort_reason",
    AbortReason,
    L,
    Scope.PROCESS,
    "why the running tour is being aborted (latched until cleared)",
)
ABORT_REASON_LAST = _key(
    "/abort_reason_last",
    AbortReason,
    L,
    Scope.PROCESS,
    "the last abort's reason, once done",
    lasting=True,
)

ICL = _key(
    "/icl",
    bool,
    L,
    Scope.PROCESS,
    "the face data stream is on (its scope's own: no other scope clears it)",
)

# -- the operator's requests (written between ticks from the console or frog-bt ctl)
HOME = _key(
    "/home",
    AbortReason,
    E,
    Scope.TOUR,
    "an operator asked the robot home: end the tour politely and dock",
)
SKIP = _key(
    "/skip",
    int,
    E,
    Scope.TOUR,
    "skip requests this tour: a stop seeing the count grow is left for the next",
)
PAUSED = _key(
    "/paused",
    bool,
    E,
    Scope.PROCESS,
    "an operator paused the tour: no new drive, no new content",
    lasting=True,
)
IN_SERVICE = _key(
    "/in_service",
    bool,
    E,
    Scope.PROCESS,
    "the robot may start tours (false: finish this one, then stay docked)",
    lasting=True,
)

# -- a person's help (the robot holds and asks; CONTRACT §7 help)
HELP = _key(
    "/help",
    Help,
    L,
    Scope.PROCESS,
    "the robot holds and waits for a person: about what, since when",
    lasting=True,
)
HELP_ANSWER = _key(
    "/help_answer",
    HelpAnswer,
    E,
    Scope.PROCESS,
    "a person's answer to /help (retry, done_by_hand), taken by the node that asked",
    lasting=True,
)
HELP_RESTORED = _key(
    "/help_restored",
    Help,
    E,
    Scope.PROCESS,
    "help still pending when the executive last stopped (restored at start-up)",
    lasting=True,
)

# -- one tour
DECLINED: Key[frozenset[int]] = _key(
    "/declined", frozenset, L, Scope.TOUR, "visitor ids who said no this tour"
)
APPROACH_FAILED: Key[dict[int, float]] = _key(
    "/approach_failed", dict, L, Scope.TOUR, "visitor id -> project time an approach of them failed"
)
SPECIAL_DONE: Key[frozenset[str]] = _key(
    "/special_done", frozenset, L, Scope.TOUR, "special-content spots announced this tour"
)
VISITOR = _key("/visitor", int, L, Scope.TOUR, "the tracked id of the visitor being guided")
TARGET = _key("/target", str, L, Scope.TOUR, "the logical POI being driven to")
WAYPOINT = _key("/waypoint", str, L, Scope.TOUR, "its time-of-day variant (POI1b)")

# -- one stop (and the introduction: a recruitment clears them too)
ENGAGEMENT = _key("/engagement", Samples, L, Scope.STOP, "the face stream's engagement samples")
ENGAGEMENT_METER = _key(
    "/engagement_meter",
    float,
    L,
    Scope.STOP,
    "the latest engagement meter level (null: an empty window)",
)
ENGAGED = _key("/engaged", bool, L, Scope.STOP, "the engagement decision (None: no face data)")
ENGAGEMENT_DECISION: Key[tuple[str, Decision]] = Key(
    "/engagement_decision",
    tuple[str, Decision],
    L,
    Scope.STOP,
    "(about, decision): the vote behind /engaged",
)
SKIPPED = _key("/skipped", str, L, Scope.STOP, "the stop being skipped, if any")

# Every key declared above, by name (the tour's own and the wire table's inputs).
ALL: dict[str, Key[Any]] = {v.name: v for v in list(globals().values()) if isinstance(v, Key)}


def by_name() -> dict[str, Key[Any]]:
    """Every key by name, with the wire table's inputs as they are now (a test may add
    one)."""
    return {**ALL, **{inp.key.name: inp.key for inp in INPUTS.values()}}


def always() -> frozenset[Key[Any]]:
    """Keys there before any tick: every input (None until a message comes) and the
    executive's."""
    keys = by_name().values()
    return frozenset(k for k in keys if k.source is not Source.LEAF)
