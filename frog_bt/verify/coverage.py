"""What recorded tours ran: per node of the tree, how often it ran and its outcomes.

The recordings' tick channel (``/frog_bt/tick``) has each tick's number and the root's
status, not every node's; so each recording is replayed on the tree
(:class:`~frog_bt.offline.replay.Replay`, which ticks exactly where the live executive
did) with a :class:`Counter` attached as an observer: after each tick it reads the nodes
the tick touched (``core.told``: ticked or stopped) and their statuses. Nodes are
counted by their place in the tree (pre-order), so one tree file counts across tours.
"""

from __future__ import annotations

import html
from collections import Counter as Tally
from dataclasses import dataclass, field
from typing import Any

from frog_bt.engine.loaded import LoadedTree
from frog_bt.model.events import Event, Ticked
from frog_bt.verify.explore import Graph, State
from frog_bt.verify.model import Model, preorder

RUNNING = "RUNNING"


@dataclass(slots=True)
class NodeCount:
    runs: int = 0  # times it started (ticked while not running)
    ticks: int = 0
    outcomes: Tally[str] = field(default_factory=Tally)  # SUCCESS, FAILURE, INVALID (stopped)


class Counter:
    """An observer of a replay (``attach`` / ``on_event`` / ``close``) that counts what
    each node of its tree did; counts add up over several replays of one tree file."""

    def __init__(self, counts: list[NodeCount]) -> None:
        self.counts = counts
        self.host: Any = None
        self._last: dict[int, str] = {}
        self._index: dict[int, int] = {}

    def attach(self, host: Any) -> None:
        self.host = host
        self._index = {id(b): i for i, b in enumerate(preorder(host.core.tree.root))}

    def on_event(self, event: Event) -> None:
        if not isinstance(event, Ticked):
            return
        seen: set[int] = set()
        for node in self.host.core.told:
            i = self._index.get(id(node))
            if i is None or i in seen:
                continue  # a node stopped and ticked again in one tick counts once
            seen.add(i)
            status = node.status.name
            before = self._last.get(i, "INVALID")
            count = self.counts[i]
            if status == "INVALID":  # stopped
                if before == RUNNING:
                    count.outcomes["INVALID"] += 1
            else:
                count.ticks += 1
                if before != RUNNING:
                    count.runs += 1
                if status != RUNNING:
                    count.outcomes[status] += 1
            self._last[i] = status

    def close(self) -> None:
        pass


# Each outcome a line can show, in its words, and what it means (KEY, printed with them).
WORDS = {"SUCCESS": "succeeded", "FAILURE": "failed", "INVALID": "stopped"}
UNFINISHED = "still running"
KEY = (
    "ran Nx: the times a node started (ticked when it was not running); each run "
    "ended in one of: succeeded (returned SUCCESS); failed (returned FAILURE); stopped "
    "(halted while running, before it returned: its parent moved on, a higher-priority "
    "branch took over, a guard or timeout cut it short, or the tour was aborted); "
    f"{UNFINISHED} (running when its recording ended). never run: no recorded tick reached it."
)


def never_run(counts: list[NodeCount]) -> list[int]:
    return [i for i, c in enumerate(counts) if c.runs == 0]


def outcomes(c: NodeCount) -> str:
    """``succeeded 3, stopped 1, still running 1``: every run's end, in words (they add
    up to the runs)."""
    parts = [f"{WORDS[k]} {c.outcomes[k]}" for k in WORDS if c.outcomes.get(k)]
    parts += [f"{k.lower()} {v}" for k, v in sorted(c.outcomes.items()) if k not in WORDS and v]
    running = c.runs - sum(c.outcomes.values())
    if running > 0:
        parts.append(f"{UNFINISHED} {running}")
    return ", ".join(parts)


def lines(model: Model, counts: list[NodeCount]) -> list[str]:
    """One line per node, indented as the tree: runs, how they ended, or never run."""
    depth = [0] * len(model.nodes)
    out = []
    for n in model.nodes:
        if n.parent >= 0:
            depth[n.index] = depth[n.parent] + 1
        c = counts[n.index]
        what = "never run" if c.runs == 0 else f"ran {c.runs}x: {outcomes(c)}"
        out.append(f"{'  ' * depth[n.index]}{n.label()}: {what}")
    return out


def page(tree: LoadedTree, model: Model, counts: list[NodeCount], files: int) -> str:
    """A self-contained HTML page (no script): the tree as a table, nodes never run marked."""
    rows = []
    depth = [0] * len(model.nodes)
    for n in model.nodes:
        if n.parent >= 0:
            depth[n.index] = depth[n.parent] + 1
        c = counts[n.index]
        cls = ' class="never"' if c.runs == 0 else ""
        rows.append(
            f'<tr{cls}><td style="padding-left:{depth[n.index]}em">'
            f"{html.escape(n.label())}</td><td>{c.runs}</td>"
            f"<td>{html.escape(outcomes(c))}</td></tr>"
        )
    never = len(never_run(counts))
    return (
        '<!doctype html><html><head><meta charset="utf-8"><title>frog-bt coverage</title>'
        "<style>body{font-family:sans-serif}td{padding:0 1em}"
        "tr.never td{color:#999;background:#fee}</style></head><body>"
        f"<h1>Coverage of {html.escape(tree.file)}</h1>"
        f"<p>{files} recordings; {len(model.nodes) - never} of {len(model.nodes)} nodes ran; "
        f"{never} never ran (shaded).</p>"
        f"<p>{html.escape(KEY)}</p>"
        "<table><tr><th>node</th><th>runs</th><th>how they ended</th></tr>"
        + "".join(rows)
        + "</table></body></html>\n"
    )


def add(total: list[NodeCount], more: list[NodeCount]) -> None:
    """Add one file's counts to ``total`` (node by node: the same tree file)."""
    for into, count in zip(total, more, strict=True):
        into.runs += count.runs
        into.ticks += count.ticks
        into.outcomes.update(count.outcomes)


Config = frozenset[int]  # the nodes running after a tick (preorder indices)


def explored_configurations(graph: Graph) -> tuple[set[Config], set[tuple[Config, Config]]]:
    """The explored states and transitions, each seen as which nodes run (what a
    recording can show of a state: it keeps no memory positions or abstract keys)."""

    def running(state: State) -> Config:
        return frozenset(i for i, v in enumerate(state[0]) if v > 0)

    configs = [running(s) for s in graph.states]
    moves = {(configs[a], configs[b]) for a, b, _ in graph.each()}
    return set(configs), moves


class Reached:
    """An observer of a replay: the configurations and moves between them that it ran."""

    def __init__(self) -> None:
        self.configs: set[Config] = set()
        self.moves: set[tuple[Config, Config]] = set()
        self.host: Any = None
        self._nodes: list[Any] = []
        self._last: Config | None = None

    def attach(self, host: Any) -> None:
        self.host = host
        self._nodes = preorder(host.core.tree.root)

    def on_event(self, event: Event) -> None:
        if not isinstance(event, Ticked):
            return
        now = frozenset(i for i, n in enumerate(self._nodes) if n.status.name == RUNNING)
        self.configs.add(now)
        if self._last is not None and self._last != now:
            self.moves.add((self._last, now))
        self._last = now

    def close(self) -> None:
        pass
