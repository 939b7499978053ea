"""Searches over an explored graph: loops (strongly connected parts), what can still reach
an end, and one-bit monitors (written before read; between A and B).

A :class:`Run` is what a broken property shows: the ticks from the start, and, for a
loop, the tick at which the loop begins (it repeats from there for ever).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from frog_bt.verify.explore import Graph, Step

Tick_ = tuple[int, Step, int]  # (from state, step, to state)


@dataclass(slots=True)
class Run:
    ticks: list[Tick_]
    loop_from: int | None = None  # index into ticks where a loop begins
    note: str = ""
    nodes: set[int] = field(default_factory=set)  # the nodes the property is about


def components(graph: Graph, keep: Callable[[int, Step, int], bool]) -> list[int]:
    """Strongly connected components of the subgraph of edges ``keep`` accepts: a
    component id per state (iterative Tarjan)."""
    n = len(graph.states)
    index = [-1] * n
    low = [0] * n
    comp = [-1] * n
    on: list[bool] = [False] * n
    stack: list[int] = []
    counter = 0
    ncomp = 0
    adj = [[dst for dst, step in graph.edges[s] if keep(s, step, dst)] for s in range(n)]
    for root in range(n):
        if index[root] != -1:
            continue
        work = [(root, 0)]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on[root] = True
        while work:
            v, k = work[-1]
            if k < len(adj[v]):
                work[-1] = (v, k + 1)
                w = adj[v][k]
                if index[w] == -1:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on[w] = True
                    work.append((w, 0))
                elif on[w]:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                u = work[-1][0]
                low[u] = min(low[u], low[v])
            if low[v] == index[v]:
                while True:
                    w = stack.pop()
                    on[w] = False
                    comp[w] = ncomp
                    if w == v:
                        break
                ncomp += 1
    return comp


def find_loop(
    graph: Graph, keep: Callable[[int, Step, int], bool], want: Callable[[Step], bool]
) -> Run | None:
    """The shortest-prefix run that ends in a loop of ``keep`` edges, one of which ``want``
    accepts; None when there is none."""
    comp = components(graph, keep)
    best: tuple[int, int, int] | None = None  # (depth of src, src, edge index)
    depth = _depths(graph)
    for src, edges in enumerate(graph.edges):
        for k, (dst, step) in enumerate(edges):
            inside = comp[src] == comp[dst] and keep(src, step, dst) and want(step)
            if inside and (best is None or depth[src] < best[0]):
                best = (depth[src], src, k)
    if best is None:
        return None
    _, src, k = best
    dst, step = graph.edges[src][k]
    prefix = graph.path(src)
    back = _path_within(graph, dst, src, lambda s, st, d: keep(s, st, d) and comp[d] == comp[src])
    return Run([*prefix, (src, step, dst), *back], loop_from=len(prefix))


def _depths(graph: Graph) -> list[int]:
    depth = [0] * len(graph.states)
    for s in range(1, len(graph.states)):
        parent = graph.parent[s][0]  # parents come first (breadth-first); a start has none
        depth[s] = depth[parent] + 1 if parent >= 0 else 0
    return depth


def _path_within(
    graph: Graph, start: int, goal: int, keep: Callable[[int, Step, int], bool]
) -> list[Tick_]:
    """A shortest path from ``start`` to ``goal`` over ``keep`` edges (empty if equal)."""
    if start == goal:
        return []
    prev: dict[int, Tick_] = {}
    queue = deque([start])
    seen = {start}
    while queue:
        s = queue.popleft()
        for dst, step in graph.edges[s]:
            if dst in seen or not keep(s, step, dst):
                continue
            seen.add(dst)
            prev[dst] = (s, step, dst)
            if dst == goal:
                out = []
                while dst != start:
                    tick = prev[dst]
                    out.append(tick)
                    dst = tick[0]
                return out[::-1]
            queue.append(dst)
    return []


def can_reach(graph: Graph, ends: set[int]) -> list[bool]:
    """Per state: can some run from it reach one of ``ends``?"""
    back: list[list[int]] = [[] for _ in graph.states]
    for src, dst, _ in graph.each():
        back[dst].append(src)
    ok = [False] * len(graph.states)
    queue = deque(ends)
    for e in ends:
        ok[e] = True
    while queue:
        s = queue.popleft()
        for p in back[s]:
            if not ok[p]:
                ok[p] = True
                queue.append(p)
    return ok


Monitor = Callable[[int, Step, bool], tuple[bool, bool]]


def monitor(graph: Graph, step_bit: Callable[[Step, bool], tuple[bool, int | None]]) -> Run | None:
    """Breadth-first over (state, bit): ``step_bit(step, bit)`` gives the bit after the
    tick and, when the tick breaks the property, the node that did; the shortest run
    that breaks it, or None."""
    starts = [(s, False) for s in graph.starts]
    prev: dict[tuple[int, bool], tuple[tuple[int, bool], Tick_]] = {}
    queue = deque(starts)
    seen = set(starts)
    while queue:
        node = queue.popleft()
        s, bit = node
        for dst, step in graph.edges[s]:
            after, broken = step_bit(step, bit)
            if broken is not None:
                ticks = [(s, step, dst)]
                cur = node
                while cur not in starts:
                    cur, tick = prev[cur]
                    ticks.append(tick)
                return Run(ticks[::-1], nodes={broken})
            nxt = (dst, after)
            if nxt not in seen:
                seen.add(nxt)
                prev[nxt] = (node, (s, step, dst))
                queue.append(nxt)
    return None
