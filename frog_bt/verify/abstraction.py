"""How verify sees each leaf: the outcomes it may have per tick, its bound, what it does to
the abstract world.

A leaf type's abstraction is :data:`TABLE`'s entry for its class name (the first class
of its MRO that has one), or a class attribute ``verify`` (an :class:`Abstraction`) of
its own, which wins: a test or a site's own leaf declares it beside its code. A leaf
with neither may run once and then succeed or fail (the robot decides).

A *rule* is one tick of the leaf: ``rule(t, node, aux, starting) -> (status, aux)``,
``aux`` the leaf's small counter (0 as it starts), ``t`` the tick (:class:`TickLike`):
it reads and writes the world, asks ``t.choose`` for an outcome (every option is
explored) and reports events. A wait is bounded: running at most ``bound`` ticks, then
its outcome is forced (its timeout); ``bound=None`` waits for the world as long as it
takes (the front end, a person's answer).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from frog_bt.verify.world import (
    ABORT,
    DOCKED,
    FAILURE,
    HOME,
    HOMING,
    IN_SERVICE,
    PAUSED,
    RUNNING,
    SKIPPED,
    STARTED,
    SUCCESS,
    By,
    Event,
    Role,
)

Option = tuple[str, By]
R, S, F = "running", "success", "failure"
STATUS = {R: RUNNING, S: SUCCESS, F: FAILURE}


class NodeView(Protocol):
    """What a rule reads of a compiled node (:class:`frog_bt.verify.model.CNode`; named
    here as a protocol so that this module does not import the model that imports it)."""

    @property
    def index(self) -> int: ...
    @property
    def abstraction(self) -> Abstraction: ...
    @property
    def dock(self) -> str: ...
    @property
    def params(self) -> dict[str, Any]: ...
    @property
    def reads_paused(self) -> bool: ...
    def type_name_in(self, *names: str) -> bool: ...


class TickLike(Protocol):
    """What a rule may do in a tick."""

    world: list[object]

    def choose(self, node: NodeView, what: str, options: Sequence[Option]) -> str:
        """One of ``options`` (each is explored); the first is taken when there is one."""
        ...

    def env(self, what: str, options: Sequence[Option]) -> str:
        """An input of this tick (the same for every leaf that reads it in the tick)."""
        ...

    def event(self, kind: Event, node: NodeView) -> None: ...

    def waits(self, node: NodeView, by: By, why: str) -> None:
        """The node holds for ``by`` (a person's resume, service_on) this tick."""
        ...


Rule = Callable[[TickLike, NodeView, int, bool], tuple[int, int]]


@dataclass(frozen=True, slots=True)
class Abstraction:
    """A leaf type as verify sees it: ``outcomes`` per tick, decided ``by`` whom, running
    at most ``bound`` ticks (None: as long as the world takes), its ``role`` to the
    built-in properties, a ``rule`` when its outcome depends on the world, and ``first``:
    the outcomes of its first tick (``(running,)``: an answer cannot come in the tick
    that asked; that leaf takes one tick and then up to ``bound`` more)."""

    outcomes: tuple[str, ...] = (S,)
    by: By = By.ROBOT
    bound: int | None = 0
    role: Role = Role.NONE
    rule: Rule | None = None
    first: tuple[str, ...] | None = None  # the outcomes as it starts (None: ``outcomes``)


def options(a: Abstraction, count: int, starting: bool = False) -> list[Option]:
    """The outcomes open on this tick: ``first`` as the leaf starts; later, running only
    while ``count`` (ticks run so far, after the first) is within the bound."""
    if starting and a.first is not None:
        return [(o, a.by) for o in a.first]
    out = [
        (o, a.by)
        for o in a.outcomes
        if o != R or a.bound is None or count < a.bound  # a bounded wait runs out
    ]
    return out or [(S, a.by)]


def plain(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """A leaf whose outcome is one of its ``outcomes`` (no effect on the world)."""
    a = n.abstraction
    count = 0 if starting else aux
    if a.role is Role.SPEAK and starting:
        t.event(Event.SPEAK, n)
    chosen = t.choose(n, "outcome", options(a, count, starting))
    return STATUS[chosen], _next(a, count, starting)


def _next(a: Abstraction, count: int, starting: bool) -> int:
    """The count after this tick: an unbounded wait's stays 0 (its ticks are alike)."""
    return count if starting or a.bound is None else min(count + 1, a.bound)


def _held(t: TickLike, n: NodeView) -> bool:
    """A leaf that reads /paused holds its action while the operator's pause lasts."""
    if n.reads_paused and t.world[PAUSED]:
        t.waits(n, By.WORLD, "paused: waits for resume")
        return True
    return False


def goal(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """A goal leaf (Navigate, ApproachVisitor): the goal goes out unless paused (aux bit 0:
    out); a pause while it is out stops the robot; then running, success or failure."""
    out, count = (0, 0) if starting else (aux & 1, aux >> 1)
    if starting and n.type_name_in("Navigate"):
        t.world[SKIPPED] = None
    if _held(t, n):
        return RUNNING, count << 1  # stopped where it is: the goal goes out again later
    if not out:
        out = 1
        if n.abstraction.role is Role.DRIVE:
            t.event(Event.DRIVE, n)
        elif n.abstraction.role is Role.APPROACH:
            t.event(Event.APPROACH, n)
            if t.world[HOME] and n.params.get("poi") == n.dock:
                t.world[HOMING] = True
    chosen = t.choose(n, "outcome", options(n.abstraction, count, starting))
    return STATUS[chosen], (_next(n.abstraction, count, starting) << 1) | out


def speak(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """StartIntroduction, AskTour: said at once, unless paused (then held until resume)."""
    if _held(t, n):
        return RUNNING, 0
    t.event(Event.SPEAK, n)
    return SUCCESS, 0


def content(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """PlayContent: starts unless paused (aux bit 0: playing), then plays or ends."""
    playing, count = (0, 0) if starting else (aux & 1, aux >> 1)
    if not playing:
        if _held(t, n):
            return RUNNING, 0
        playing = 1
        t.event(Event.CONTENT, n)
    fresh = not (aux & 1)  # its first tick playing
    chosen = t.choose(n, "outcome", options(n.abstraction, count, fresh))
    return STATUS[chosen], (_next(n.abstraction, count, fresh) << 1) | playing


def docking(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """Docking: at once when the robot already is where asked; else running, docked or
    undocked (the world follows), or failed."""
    dock = n.params.get("action") == "dock"
    if starting:
        if t.world[DOCKED] == dock:
            return SUCCESS, 0
        t.event(Event.DOCK if dock else Event.UNDOCK, n)
        if dock and t.world[HOME]:
            t.world[HOMING] = True
    chosen = t.choose(n, "outcome", options(n.abstraction, aux, starting))
    if chosen == S:
        t.world[DOCKED] = dock
    return STATUS[chosen], _next(n.abstraction, aux, starting)


def must_abort(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    if t.world[ABORT]:
        return SUCCESS, 0
    if not t.world[STARTED]:
        return FAILURE, 0
    if t.world[HOME] or t.env("battery low or fault", [("no", By.QUIET), ("yes", By.WORLD)]) == (
        "yes"
    ):
        t.world[ABORT] = True
        return SUCCESS, 0
    return FAILURE, 0


def clear_abort(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    t.world[ABORT] = t.world[HOME] = t.world[HOMING] = False
    return SUCCESS, 0


def give_up(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    t.world[STARTED] = False
    return FAILURE, 0


def tour_status(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    started = n.params.get("state") == "started"
    if started:
        t.event(Event.TOUR_STARTED, n)
    t.world[STARTED] = started
    return SUCCESS, 0


def wait_in_service(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    if t.world[IN_SERVICE]:
        return SUCCESS, 0
    t.waits(n, By.WORLD, "out of service: waits for service_on")
    return RUNNING, 0


def ask_for_help(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """AskForHelp: asks at once (``fault``: while a fault persists; ``restored``: never, as
    verify starts fresh), holds, and takes a person's ``retry`` (FAILURE) or
    ``done_by_hand`` (SUCCESS: the robot is where the step should have left it)."""
    about = n.params.get("about")
    asking = 0 if starting else aux
    if about == "restored":
        return SUCCESS, 0
    if about == "fault":
        fault = t.env("fault", [("no", By.QUIET), ("yes", By.WORLD)]) == "yes"
        if not fault:
            return SUCCESS, 0
    if not asking:
        t.event(Event.HELP, n)
        if t.world[HOME]:
            t.world[HOMING] = True
        t.waits(n, By.WORLD, "asks a person")
        return RUNNING, 1
    answers = [("none", By.WORLD), ("retry", By.WORLD)]
    if about != "fault":
        answers.append(("done_by_hand", By.WORLD))
    answer = t.choose(n, "answer", answers)
    if answer == "retry":
        return FAILURE, 0
    if answer == "done_by_hand":
        t.world[DOCKED] = about != "undock"
        return SUCCESS, 0
    return RUNNING, 1


def wait_event(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """WaitEvent: the event arrives (the world), or, once its bound ran out, the wait ends
    with ``on_timeout``."""
    if starting:
        return RUNNING, 0  # an event that arrives after it starts
    choices: list[Option] = [(S, By.WORLD)]
    timeout = str(n.params.get("on_timeout", "failure"))
    if timeout != S:
        choices.append((timeout, By.ROBOT))
    return STATUS[t.choose(n, "outcome", choices)], 0


def at_poi(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    """AtPoi: a robot on its charger is at the dock's waypoint; anywhere else, where it
    is (by /pose) is the robot's: at the POI or not."""
    if t.world[DOCKED] and n.params.get("poi") == n.dock:
        return SUCCESS, 0
    return STATUS[t.choose(n, "outcome", [(S, By.ROBOT), (F, By.ROBOT)])], 0


def skip_stop(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    t.world[SKIPPED] = n.params.get("poi")
    return SUCCESS, 0


def skipped(t: TickLike, n: NodeView, aux: int, starting: bool) -> tuple[int, int]:
    return (SUCCESS if t.world[SKIPPED] == n.params.get("poi") else FAILURE), 0


W = By.WORLD
TABLE: dict[str, Abstraction] = {
    "MustAbort": Abstraction(rule=must_abort),
    "ClearAbort": Abstraction(rule=clear_abort),
    "GiveUp": Abstraction((F,), rule=give_up),
    "ConfirmResume": Abstraction(),  # verify starts fresh: no checkpoint to resume
    "TourStatus": Abstraction(rule=tour_status),
    "WaitInService": Abstraction(rule=wait_in_service, role=Role.IDLE),
    "WaitFrontendIdle": Abstraction((R, S), W, None, Role.IDLE),
    "AskForHelp": Abstraction(rule=ask_for_help, role=Role.HELP, bound=None),
    "Navigate": Abstraction((R, S, F), role=Role.DRIVE, rule=goal, first=(R,)),
    "ApproachVisitor": Abstraction((R, S, F), role=Role.APPROACH, rule=goal, first=(R,)),
    "Docking": Abstraction((R, S, F), rule=docking, first=(R,)),
    "AtPoi": Abstraction((S, F), rule=at_poi),
    "SkipStop": Abstraction(rule=skip_stop),
    "Skipped": Abstraction(rule=skipped),
    "SeekVisitor": Abstraction((R, S), W, None),
    "StartIntroduction": Abstraction(role=Role.SPEAK, rule=speak),
    "AskTour": Abstraction(role=Role.SPEAK, rule=speak),
    "WaitEvent": Abstraction((R, S), W, rule=wait_event),
    "WaitAnswer": Abstraction((R, S, F), W, first=(R,)),
    "DecideEngagement": Abstraction(),
    "Engaged": Abstraction((S, F), W),
    "VisitorFollows": Abstraction((R, S, F), W, first=(R, S)),
    "PlayContent": Abstraction((R, S), W, role=Role.CONTENT, rule=content, first=(R,)),
    "FinishPoi": Abstraction(),
}
DEFAULT = Abstraction((R, S, F), first=(R, S, F))


def abstraction_of(cls: type) -> tuple[Abstraction, bool]:
    """The abstraction of a leaf class, and whether it was declared (not the default)."""
    own = cls.__dict__.get("verify")
    if isinstance(own, Abstraction):
        return own, True
    for base in cls.__mro__:
        if base.__name__ in TABLE:
            return TABLE[base.__name__], True
        inherited = base.__dict__.get("verify")
        if isinstance(inherited, Abstraction):
            return inherited, True
    return DEFAULT, False
