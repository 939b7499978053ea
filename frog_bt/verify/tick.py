"""One tick of a compiled tree, as py_trees ticks the real one, with every choice asked of
an oracle.

The node state is one int per node: 0 not running (py_trees' INVALID, or ended),
``1 + aux`` running (``aux``: a memory composite's current child, a retry's failures, a
leaf's counter), -1 a synchronised Parallel's child that succeeded. A node that ends or
is stopped leaves none of its subtree running; a node that starts, starts its subtree
afresh. Those are the py_trees 2 rules of ``Sequence``, ``Selector``, ``Parallel`` and
``Retry`` (py_trees' ``composites.py`` and ``decorators.py``), written over a tuple so
that a state hashes.

Before the tree ticks, the operator may give one command (applied at the tick boundary,
as :class:`~frog_bt.engine.operator.Operator` does, with its conditions).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from frog_bt.verify.abstraction import NodeView, Option, plain
from frog_bt.verify.model import CNode, Kind, Model
from frog_bt.verify.world import (
    ABORT,
    FAILURE,
    HOME,
    HOMING,
    IN_SERVICE,
    PAUSED,
    RUNNING,
    STARTED,
    SUCCESS,
    By,
    Event,
)

State = tuple[tuple[int, ...], tuple[object, ...]]


@dataclass(frozen=True, slots=True)
class Choice:
    node: int  # -1: an input of the tick, not a node's
    what: str
    value: str
    by: By


@dataclass(slots=True)
class Step:
    """What one tick did: the choices taken, the events, the nodes ticked (in order, with
    whether each started), the world when each event happened."""

    choices: list[Choice] = field(default_factory=list)
    events: list[tuple[Event, int, tuple[object, ...]]] = field(default_factory=list)
    ticked: list[tuple[int, bool]] = field(default_factory=list)
    waits: list[tuple[int, str]] = field(default_factory=list)
    started_tour: bool = False  # the tour was under way as the tick began

    @property
    def quiet(self) -> bool:
        """No person, front end or operator did anything, and nothing waited for one."""
        return not self.waits and all(c.by is not By.WORLD for c in self.choices)


class Oracle:
    """Replays ``prefix`` (option indexes), then takes the first option, noting how many
    each choice point had (the explorer branches on the rest)."""

    def __init__(self, prefix: Sequence[int]) -> None:
        self.prefix = prefix
        self.taken: list[int] = []
        self.widths: list[int] = []

    def pick(self, width: int) -> int:
        k = len(self.taken)
        index = self.prefix[k] if k < len(self.prefix) else 0
        self.taken.append(index)
        self.widths.append(width)
        return index


def commands(world: Sequence[object]) -> list[Option]:
    """The operator commands the executive accepts now (CONTRACT §7, operator.py)."""
    out: list[Option] = [("none", By.QUIET)]
    touring = bool(world[STARTED])
    if touring and not world[HOME] and not world[ABORT]:
        out.append(("home", By.WORLD))
    if world[PAUSED]:
        out += [("resume", By.WORLD), ("pause ran out", By.WORLD)]
    elif touring:
        out.append(("pause", By.WORLD))
    out.append(("service_on" if not world[IN_SERVICE] else "service_off", By.WORLD))
    return out


def apply_command(world: list[object], command: str) -> None:
    if command == "home":
        world[HOME], world[PAUSED] = True, False
    elif command == "pause":
        world[PAUSED] = True
    elif command == "resume":
        world[PAUSED] = False
    elif command == "pause ran out":
        world[PAUSED] = False
        if world[STARTED] and not world[HOME] and not world[ABORT]:
            world[HOME] = True
    elif command in ("service_off", "service_on"):
        world[IN_SERVICE] = command == "service_on"
    if not world[HOME]:
        world[HOMING] = False


class Tick:
    """One tick from ``state`` with ``oracle``'s choices; :meth:`run` gives the next state."""

    def __init__(self, model: Model, state: State, oracle: Oracle) -> None:
        self.model = model
        self.nodes = list(state[0])
        self.world = list(state[1])
        self.oracle = oracle
        self.step = Step(started_tour=bool(self.world[STARTED]))
        self._env: dict[str, str] = {}

    # ------------------------------------------------------------ what rules may do

    def _pick(self, node: int, what: str, options: Sequence[Option]) -> str:
        index = self.oracle.pick(len(options)) if len(options) > 1 else 0
        value, by = options[index]
        if len(options) > 1:
            self.step.choices.append(Choice(node, what, value, by))
        return value

    def choose(self, node: NodeView, what: str, options: Sequence[Option]) -> str:
        return self._pick(node.index, what, options)

    def env(self, what: str, options: Sequence[Option]) -> str:
        if what not in self._env:
            self._env[what] = self._pick(-1, what, options)
        return self._env[what]

    def event(self, kind: Event, node: NodeView) -> None:
        self.step.events.append((kind, node.index, tuple(self.world)))

    def waits(self, node: NodeView, by: By, why: str) -> None:
        self.step.waits.append((node.index, why))

    # ------------------------------------------------------------ the tick

    def run(self) -> tuple[State, Step]:
        command = self._pick(-1, "operator", commands(self.world))
        apply_command(self.world, command)
        self.tick(0)
        return (tuple(self.nodes), tuple(self.world)), self.step

    def _clear(self, start: int, end: int) -> None:
        nodes = self.nodes
        for i in range(start, end):
            if nodes[i]:
                nodes[i] = 0

    def tick(self, i: int) -> int:
        n = self.model.nodes[i]
        aux = self.nodes[i]
        starting = aux <= 0
        if starting:
            self._clear(i + 1, n.end)
            aux = 0
        else:
            aux -= 1
        self.step.ticked.append((i, starting))
        status, aux = self._dispatch(n, aux, starting)
        if status == RUNNING:
            self.nodes[i] = aux + 1
        else:
            self._clear(i + 1, n.end)
            self.nodes[i] = -1 if (status == SUCCESS and n.keeps_success) else 0
        return status

    def _dispatch(self, n: CNode, aux: int, starting: bool) -> tuple[int, int]:
        kind = n.kind
        if kind is Kind.LEAF:
            rule = n.abstraction.rule or plain
            return rule(self, n, aux, starting)
        if kind is Kind.SEQUENCE:
            return self._sequence(n, aux)
        if kind is Kind.SELECTOR:
            return self._selector(n, aux)
        if kind is Kind.PARALLEL:
            return self._parallel(n)
        if kind is Kind.RETRY:
            return self._retry(n, aux)
        if kind is Kind.SKIP and not starting and self._skip_asked(n):
            self._clear(n.index + 1, n.end)
            return SUCCESS, 0
        status = self.tick(n.children[0])
        if kind is Kind.FAILURE_IS_SUCCESS and status == FAILURE:
            return SUCCESS, 0
        timeout = [("no", By.QUIET), ("timed out", By.ROBOT)]
        if (
            kind is Kind.TIMEOUT
            and status == RUNNING
            and self.choose(n, "timeout", timeout) != "no"
        ):
            return FAILURE, 0
        return status, 0

    def _skip_asked(self, n: CNode) -> bool:
        w = self.world
        if not w[STARTED] or w[HOME] or w[ABORT]:
            return False  # the executive refuses skip then
        return self.choose(n, "operator", [("none", By.QUIET), ("skip", By.WORLD)]) == "skip"

    def _sequence(self, n: CNode, aux: int) -> tuple[int, int]:
        children = n.children
        start = aux if n.memory else 0
        for k in range(start, len(children)):
            status = self.tick(children[k])
            if status != SUCCESS:
                if not n.memory:
                    for later in children[k + 1 :]:
                        self._clear(later, self.model.nodes[later].end)
                return status, (k if n.memory else 0)
        return SUCCESS, 0

    def _selector(self, n: CNode, aux: int) -> tuple[int, int]:
        children = n.children
        start = aux if n.memory else 0
        for k in range(start, len(children)):
            status = self.tick(children[k])
            if status != FAILURE:
                for later in children[k + 1 :]:  # a higher priority took over
                    self._clear(later, self.model.nodes[later].end)
                return status, (k if n.memory else 0)
        return FAILURE, 0

    def _parallel(self, n: CNode) -> tuple[int, int]:
        statuses = []
        for c in n.children:
            if n.synchronise and n.policy_all and self.nodes[c] == -1:
                statuses.append(SUCCESS)
                continue
            statuses.append(self.tick(c))
        if FAILURE in statuses:
            return FAILURE, 0
        if n.policy_all:
            return (SUCCESS if all(s == SUCCESS for s in statuses) else RUNNING), 0
        return (SUCCESS if SUCCESS in statuses else RUNNING), 0

    def _retry(self, n: CNode, failures: int) -> tuple[int, int]:
        status = self.tick(n.children[0])
        if status != FAILURE:
            return status, failures
        if n.attempts is not None and failures + 1 >= n.attempts:
            return FAILURE, 0
        self.step.events.append((Event.RETRY, n.index, tuple(self.world)))
        # an unbounded retry's count changes nothing: keep it out of the state
        return RUNNING, (failures + 1 if n.attempts is not None else 0)
