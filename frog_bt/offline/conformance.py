"""Conformance with the field: is every step a recording took one the explorer allows?

Each recording is replayed on the tree verify explored, built afresh by the same loader
(:class:`~frog_bt.offline.replay.Replay` ticks exactly where the live executive did),
with a :class:`Steps` observer: after each tick it reads which nodes run. A state is
seen as which nodes run (what a recording can show: it keeps no memory positions,
counters or abstract keys), so a step is allowed when the explored graph has a
transition between the two configurations (or the configuration holds: a tick that
changed nothing the recording shows, a wait, which on the robot takes as many ticks as
its seconds and in the exploration as few as it can; verify leaves durations out). The
first step outside names the recording, the tick and the node: the world's abstraction
missed something the robot did. Only the first per recording is told; what follows it
is its consequence.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.model.events import Event, Ticked
from frog_bt.verify.coverage import Config, explored_configurations
from frog_bt.verify.explore import Graph
from frog_bt.verify.model import Model, preorder

RUNNING = "RUNNING"
START: Config = frozenset({-1})  # before a recording's first tick (any start of the graph)


@dataclass(frozen=True, slots=True)
class Outside:
    """A recorded step the explorer does not allow."""

    recording: Path
    tick: int
    node: str  # the node, as ``label()`` shows it
    what: str  # "running" or "not running" where every allowed step says otherwise

    def line(self) -> str:
        return (
            f"{self.recording}: tick {self.tick}: {self.node} {self.what}: "
            "a step the exploration does not allow"
        )


class Steps:
    """An observer of a replay: the configurations after each tick, with its number."""

    def __init__(self) -> None:
        self.seen: list[tuple[int, Config]] = []
        self._nodes: list[Any] = []
        self.host: Any = None

    def attach(self, host: Any) -> None:
        self.host = host
        self._nodes = preorder(host.core.tree.root)

    def on_event(self, event: Event) -> None:
        if isinstance(event, Ticked):
            running = frozenset(i for i, n in enumerate(self._nodes) if n.status.name == RUNNING)
            self.seen.append((event.tick, running))

    def close(self) -> None:
        pass


class Allowed:
    """The steps the explored graph allows, as configurations of running nodes."""

    def __init__(self, graph: Graph, model: Model) -> None:
        self.model = model
        configs, moves = explored_configurations(graph)
        self.configs = configs
        self.after: dict[Config, set[Config]] = {}
        for a, b in moves:
            self.after.setdefault(a, set()).add(b)
        # a recording starts fresh or, after a restart, from a checkpoint: from any start
        starts = {
            frozenset(i for i, v in enumerate(graph.states[s][0]) if v > 0) for s in graph.starts
        }
        self.after[START] = set().union(*(self.after.get(s, set()) for s in starts))
        self.ever = frozenset().union(*configs)  # the nodes some explored state runs

    def first_outside(self, path: Path, seen: list[tuple[int, Config]]) -> Outside | None:
        before = START
        for tick, now in seen:
            if now == before and now in self.configs:
                continue  # a wait: the ticks a wait takes are seconds, which verify leaves out
            allowed = self.after.get(before, set())
            if now not in allowed:
                return self._outside(path, tick, before, now, allowed or self.configs)
            before = now
        return None

    def _outside(
        self, path: Path, tick: int, before: Config, now: Config, allowed: Iterable[Config]
    ) -> Outside:
        """Named at the first node (pre-order) running now that runs in no explored state;
        else at a node in which ``now`` differs from the allowed configuration nearest it:
        one this step changed, a leaf first (the composites above it follow it)."""
        never = now - self.ever
        if never:
            return Outside(path, tick, self.model.nodes[min(never)].label(), "running")
        nearest = min(allowed, key=lambda c: (len(c ^ now), sorted(c ^ now)))
        diff = nearest ^ now
        changed = (diff & (now ^ before)) or diff
        leaves = {i for i in changed if not self.model.nodes[i].children}
        index = min(leaves or changed)
        what = "running" if index in now else "not running"
        return Outside(path, tick, self.model.nodes[index].label(), what)


def conformance(
    graph: Graph,
    model: Model,
    site: Site,
    fresh: Callable[[], LoadedTree],
    paths: Iterable[Path],
    on_error: Callable[[Path, str], None],
) -> tuple[int, list[Outside]]:
    """Replay every recording (each on a ``fresh()`` tree) and check each of its steps
    against ``graph``: how many were replayed, and the first step outside of each that
    left the exploration. A recording that cannot be replayed goes to ``on_error``."""
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import ReplayError

    allowed = Allowed(graph, model)
    files = 0
    outside: list[Outside] = []
    for path in paths:
        try:
            replay = Replay(path, site, fresh())
        except (ReplayError, OSError) as exc:
            on_error(path, str(exc))
            continue
        steps = Steps()
        replay.observers.attach(replay, [steps])
        replay.run()
        files += 1
        found = allowed.first_outside(path, steps.seen)
        if found is not None:
            outside.append(found)
    return files, outside
