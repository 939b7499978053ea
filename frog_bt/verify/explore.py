"""What an exploration finds: the graph of every state reached, each transition with the
tick that made it (:class:`Step`), and the choices that tick took of the world.

The explorer (:mod:`.real`) enumerates every combination of choices of one tick with an
:class:`Oracle` (it replays a prefix of option indexes; each choice point beyond it
branches); states are hashed into one table, so each is expanded once and the first
path found to any state is a shortest one. Every transition is kept (its target and its
:class:`Step`) for the properties that look at the graph: loops, what can still be
reached, what was written before a read.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

from frog_bt.verify.model import Model
from frog_bt.verify.world import By, Event

MAX_STATES = 2_000_000

# A state as the properties see it: per node (pre-order) 0 not running, 1 running, 2
# running with its action out (a goal, content playing); the world (:mod:`.world`).
State = tuple[tuple[int, ...], tuple[object, ...]]


class TooBig(Exception):
    """More states than the limit: the tree is too big to verify whole."""


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


@dataclass(slots=True)
class Graph:
    model: Model
    states: list[State] = field(default_factory=list)
    parent: list[tuple[int, int]] = field(default_factory=list)  # (state, edge index in it)
    edges: list[list[tuple[int, Step]]] = field(default_factory=list)
    seconds: float = 0.0
    starts: list[int] = field(default_factory=lambda: [0])  # a restart's too

    @property
    def transitions(self) -> int:
        return sum(len(e) for e in self.edges)

    def path(self, state: int) -> list[tuple[int, Step, int]]:
        """The shortest run to ``state``: (from, step, to) per tick."""
        out = []
        while self.parent[state][0] >= 0:
            src, k = self.parent[state]
            out.append((src, self.edges[src][k][1], state))
            state = src
        return out[::-1]

    def each(self) -> Iterator[tuple[int, int, Step]]:
        for src, edges in enumerate(self.edges):
            for dst, step in edges:
                yield src, dst, step
