"""Breadth-first over every state a compiled tree can reach.

From each state every combination of choices of one tick is enumerated (an
:class:`~frog_bt.verify.tick.Oracle` replays a prefix of option indexes, and each choice
point beyond it branches); states are hashed into one table, so each is expanded once
and the first path found to any state is a shortest one. Every transition is kept
(its target and its :class:`~frog_bt.verify.tick.Step`) for the properties that look at
the graph: loops, what can still be reached, what was written before a read.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from frog_bt.verify.model import Model
from frog_bt.verify.tick import Oracle, State, Step, Tick
from frog_bt.verify.world import INITIAL

MAX_STATES = 2_000_000


class TooBig(Exception):
    """More states than the limit: the tree is too big to verify whole."""


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


def successors(model: Model, state: State) -> Iterator[tuple[State, Step]]:
    """Every next state with the tick that led there (all choices enumerated)."""
    pending: list[list[int]] = [[]]
    while pending:
        prefix = pending.pop()
        oracle = Oracle(prefix)
        nxt, step = Tick(model, state, oracle).run()
        yield nxt, step
        for k in range(len(prefix), len(oracle.widths)):
            for alt in range(1, oracle.widths[k]):
                pending.append([*oracle.taken[:k], alt])


def explore(
    model: Model,
    on_step: Callable[[int, Step, int, State], None] | None = None,
    limit: int = MAX_STATES,
) -> Graph:
    """Every reachable state, breadth-first; ``on_step(src, step, dst, state)`` sees each
    transition as it is found (in breadth-first order: the first one to break a safety
    property ends the shortest run that does)."""
    started = time.perf_counter()
    initial: State = (tuple(0 for _ in model.nodes), INITIAL)
    graph = Graph(model, [initial], [(-1, -1)], [])
    index = {initial: 0}
    head = 0
    while head < len(graph.states):
        state = graph.states[head]
        edges: list[tuple[int, Step]] = []
        graph.edges.append(edges)
        for nxt, step in successors(model, state):
            dst = index.get(nxt)
            if dst is None:
                dst = len(graph.states)
                if dst >= limit:
                    raise TooBig(f"more than {limit} states")
                index[nxt] = dst
                graph.states.append(nxt)
                graph.parent.append((head, len(edges)))
            edges.append((dst, step))
            if on_step is not None:
                on_step(head, step, dst, nxt)
        head += 1
    graph.seconds = time.perf_counter() - started
    return graph
