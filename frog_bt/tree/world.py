"""What a node type tells ``frog-bt verify`` about itself: its world interface and its state.

``frog-bt verify`` ticks the real tree (:mod:`frog_bt.verify.real`); only the world is
abstracted. Each node type says, on its class, as ``world = World(...)``:

* ``inputs``: the parts of the world it listens to (:class:`Channel`): what the explorer
  chooses for it at each tick, from a finite set (the robot's answer to its goal, the
  front end's events, a visitor, the diagnostics, its wait running out);
* ``state``: the instance fields it keeps between ticks (set in ``initialise`` or
  ``update``), with ``times`` (project-clock times among them: encoded relative to now)
  and ``indexes`` (front-end event indexes: relative to the newest event); ``copy``:
  the mutable ones, copied on snapshot and restore. A field it keeps and does not
  declare is an error verify reports by class;
* ``timer``: when its wait runs out (project clock): while that is ahead, the explorer
  may make it run out (``fire``: the node's own times moved back by the seconds left,
  by default every field in ``times``; the clock itself never moves, so the other
  waits stay pending); ``frontend``: the front-end events it may be sent now; ``docking``: the
  docking states the robot may report to it now (``/docking/state``); ``active``: the field
  set while its action is out (a goal, content playing); ``waits``: while it runs it
  waits for a person or the front end (not for the robot);
* ``late``: the keys a decorator reads only once its child has succeeded (whatever its
  child's scope cleared is not read from before);
* ``truthy``: the keys it reads only as true or false (None reads as false);
* ``ignores``: keys it reads, and fields of its ``state``, whose value changes none of
  its outcomes under its world abstraction (``why`` says why): not state on its account;
* ``counts``: (key, field): a count on the board it remembers in ``field`` as it starts
  and compares with later: only the count since its start is state (and none while no
  node that counts it runs, when every reader of the key counts it so);
* ``passes``: a decorator that succeeds only when its child succeeded (a checkpoint:
  unless it skips its child, resumed);
* ``sets``: the keys it surely writes as it succeeds (what was there before is not read
  after it);
* ``diagnostics``: the diagnostics it tells apart (``ok``, ``battery low``, ``fault``):
  the explorer offers those when it is the first node of a tick to read them;
* ``views``: (key, view): of a key's value it decides only on ``view(value)`` (the rest
  it only says in words): when every reader of the key says so, the views are state;
* ``places``: the waypoints it compares the robot's pose with: where the robot is, is
  state only as whether it is at each waypoint some node compares with;
* ``people``: keys (and its own fields) that hold a person's id: people are alike, so
  verify keeps only whether an id is the current visitor's (``/visitor``);
* ``role``: what it is to the built-in properties; ``why``: where it abstracts a number
  (engagement, a distance), the reason.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any

__all__ = ["Channel", "Role", "World"]


class Channel(enum.Enum):
    """A part of the world the explorer drives."""

    GOAL = "the robot's answer to a goal"
    DOCKING = "the docking state"
    FRONTEND = "the front end's events"
    VISITOR = "a visitor facing the robot, following, answering"
    FACES = "a visitor's face: engaged or not"
    DIAGNOSTICS = "battery and faults"
    POSE = "where the robot is"
    OPERATOR = "the operator's commands"
    CLOCK = "a wait running out"


class Role(enum.Enum):
    """What a leaf is to the built-in properties."""

    NONE = "none"
    DRIVE = "drive"  # sends the robot across the floor to a POI (a pause holds it)
    APPROACH = "approach"  # drives the robot up to a visitor (a pause holds it)
    CONTENT = "content"  # plays a stop's content (a pause holds its start)
    SPEAK = "speak"  # says something to the visitor at once (introduction, question)
    DOCK = "dock"
    UNDOCK = "undock"
    IDLE = "idle"  # waits, with no tour, for the next one
    HELP = "help"  # holds and asks a person


@dataclass(frozen=True, slots=True)
class World:
    """A node type's world interface and state, as verify sees them."""

    inputs: tuple[Channel, ...] = ()
    state: tuple[str, ...] = ()
    times: tuple[str, ...] = ()
    indexes: tuple[str, ...] = ()
    copy: tuple[str, ...] = ()
    timer: Callable[[Any], float | None] | None = None
    fire: Callable[[Any, float], None] | None = None  # (node, seconds left): run out now
    frontend: Callable[[Any], tuple[Any, ...]] | None = None
    docking: Callable[[Any], tuple[str, ...]] | None = None
    active: str = ""
    waits: bool = False
    role: Role = Role.NONE
    key: Callable[[Any], Hashable] | None = None  # its own encoding of its state
    late: tuple[str, ...] = ()  # keys it reads only once its child succeeded (a decorator)
    truthy: tuple[str, ...] = ()  # keys it reads only as true or false (None is false)
    ignores: tuple[str, ...] = ()  # keys it reads whose value changes no outcome of it
    people: tuple[str, ...] = ()  # keys and fields holding a person's id
    sets: tuple[str, ...] = ()  # keys it surely writes as it succeeds
    passes: bool = False  # a decorator: it succeeds only when its child succeeded
    diagnostics: tuple[str, ...] = ("ok", "battery low", "fault")
    views: tuple[tuple[str, Callable[[Any], Hashable]], ...] = ()  # (key, what it decides on)
    places: Callable[[Any], tuple[str, ...]] | None = None  # waypoints it compares with
    counts: tuple[tuple[str, str], ...] = ()  # (key, field): a count since it started
    why: str = ""


def world_of(cls: type) -> World | None:
    """The world interface a node type declares (inherited from a base), or None."""
    found = getattr(cls, "world", None)
    return found if isinstance(found, World) else None
