"""The built-in properties of a tour tree, by name, in museum terms.

Safety properties are checked on each transition as the exploration finds it (so the
first that breaks one ends a shortest run); the others look at the whole graph: loops,
what can still reach an end, what was written before it was read.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from frog_bt.model.key import Source
from frog_bt.model.keys import by_name
from frog_bt.verify.explore import Graph, State, Step
from frog_bt.verify.graph import Run, can_reach, find_loop, monitor
from frog_bt.verify.model import Model
from frog_bt.verify.world import (
    DOCKED,
    HOME,
    HOMING,
    IN_SERVICE,
    PAUSED,
    STARTED,
    Event,
    Role,
)

PAUSE_HOLDS = (Event.DRIVE, Event.APPROACH, Event.CONTENT, Event.SPEAK)  # what a pause holds

MEANING = {
    "ends-well": "every run ends docked and idle, or holds and asks a person for help: no "
    "trap, no loop the robot repeats on its own",
    "home-obeyed": "after home, no new stop content starts, and the robot reaches the dock "
    "sequence (or asks for help) within a bounded number of ticks",
    "service-off-obeyed": "between service_off and service_on no new tour starts: no `tour "
    "started`, no undock outside a tour already under way",
    "pause-obeyed": "while paused, no new goal (a drive to a stop, an approach), no new "
    "content and nothing new said to the visitor (CONTRACT §7)",
    "no-content-while-driving": "no content plays and the visitor is not addressed while a "
    "drive is under way",
    "bounded-retries": "each retry loop ends: no retry repeats for ever on the robot's own "
    "failures",
    "no-dead-reads": "every key a node reads, optional reads included, is written before it "
    "in at least one run",
}
BUILT_IN = tuple(MEANING)


@dataclass(slots=True)
class Broken:
    name: str
    meaning: str
    run: Run


def _running(state: State, model: Model, role: Role) -> list[int]:
    """Leaves of ``role`` running with their action out (2 in the state's view of the
    nodes, :meth:`~frog_bt.verify.real.Real.view`)."""
    nodes = state[0]
    return [n.index for n in model.nodes if n.role is role and nodes[n.index] == 2]


class Safety:
    """Watches each transition; keeps the first (shortest) that breaks each property."""

    def __init__(self, model: Model) -> None:
        self.model = model
        self.first: dict[str, tuple[int, Step, int, int, str]] = {}
        self.drives = [n.index for n in model.nodes if n.role is Role.DRIVE]
        self.contents = [n.index for n in model.nodes if n.role is Role.CONTENT]
        self.idle = [n.index for n in model.nodes if n.role is Role.IDLE]

    def _hit(self, name: str, src: int, step: Step, dst: int, node: int, note: str) -> None:
        if name not in self.first:
            self.first[name] = (src, step, dst, node, note)

    def __call__(self, src: int, step: Step, dst: int, state: State) -> None:
        for kind, node, world in step.events:
            starts = kind is Event.TOUR_STARTED or (
                kind is Event.UNDOCK and not step.started_tour  # not within a tour under way
            )
            if starts and not world[IN_SERVICE]:
                self._hit(
                    "service-off-obeyed",
                    src,
                    step,
                    dst,
                    node,
                    f"{kind.value} while out of service",
                )
            if kind in PAUSE_HOLDS and world[PAUSED]:
                self._hit("pause-obeyed", src, step, dst, node, f"{kind.value} while paused")
            if kind is Event.CONTENT and world[HOME]:
                self._hit("home-obeyed", src, step, dst, node, "content started after home")
        nodes, world = state
        drive = next((i for i in self.drives if nodes[i] > 0 and (nodes[i] - 1) & 1), None)
        if drive is not None:
            content = next((i for i in self.contents if nodes[i] > 0 and (nodes[i] - 1) & 1), None)
            speak = next((n for k, n, _ in step.events if k is Event.SPEAK), None)
            other = content if content is not None else speak
            if other is not None:
                self._hit(
                    "no-content-while-driving",
                    src,
                    step,
                    dst,
                    other,
                    f"{self.model.nodes[other].label()} while "
                    f"{self.model.nodes[drive].label()} drives",
                )
        if not world[STARTED] and not world[DOCKED]:
            idle = next((i for i in self.idle if nodes[i] > 0), None)
            if idle is not None:
                self._hit(
                    "ends-well", src, step, dst, idle, "idle, waiting for a tour, off the dock"
                )

    def broken(self, graph: Graph) -> dict[str, Run]:
        out = {}
        for name, (src, step, dst, node, note) in self.first.items():
            out[name] = Run([*graph.path(src), (src, step, dst)], note=note, nodes={node})
        return out


def _ends(graph: Graph, model: Model) -> set[int]:
    """States in which a run has ended well: idle at the dock, or asking a person."""
    idle = [n.index for n in model.nodes if n.role is Role.IDLE]
    help_ = [n.index for n in model.nodes if n.role is Role.HELP]
    out = set()
    for s, (nodes, world) in enumerate(graph.states):
        asking = any(nodes[i] > 0 for i in help_)
        if asking or (world[DOCKED] and not world[STARTED] and any(nodes[i] > 0 for i in idle)):
            out.add(s)
    return out


def ends_well(graph: Graph, model: Model) -> Run | None:
    loop = find_loop(graph, lambda s, step, d: step.quiet, lambda step: True)
    if loop is not None:
        loop.note = "a loop the robot repeats on its own, with no person, front end or operator"
        return loop
    ok = can_reach(graph, _ends(graph, model))
    for s in range(len(graph.states)):  # breadth-first order: the shortest first
        if not ok[s]:
            return Run(
                graph.path(s), note="from here no run ends docked and idle, or asks for help"
            )
    return None


def bounded_retries(graph: Graph, model: Model) -> Run | None:
    def retried(step: Step) -> bool:
        return any(kind is Event.RETRY for kind, _, _ in step.events)

    loop = find_loop(graph, lambda s, step, d: step.quiet, retried)
    if loop is not None:
        retries = [
            n
            for _, step, _ in loop.ticks[loop.loop_from or 0 :]
            for k, n, _ in step.events
            if k is Event.RETRY
        ]
        unbounded = [n for n in retries if model.nodes[n].attempts is None]
        retry = (unbounded or retries)[0]
        loop.nodes = {retry}
        loop.note = f"{model.nodes[retry].label()} retries for ever on the robot's own failures"
    return loop


def home_obeyed(graph: Graph, model: Model) -> Run | None:
    def pending(s: int) -> bool:
        world = graph.states[s][1]
        return bool(world[HOME]) and not world[HOMING]

    loop = find_loop(graph, lambda s, step, d: pending(s) and pending(d), lambda step: True)
    if loop is not None:
        loop.note = "home asked, and the dock sequence is never reached"
    return loop


def no_dead_reads(graph: Graph, model: Model) -> list[Run]:
    """One run per (node, key) read that no run writes before: the run shows the read."""
    declared = by_name()
    ticked: set[int] = set()
    for _, _, step in graph.each():
        ticked.update(i for i, _ in step.ticked)
    readers: dict[str, set[int]] = {}
    for n in model.nodes:
        for name in n.reads:
            key = declared.get(name)
            if key is not None and key.source is Source.LEAF and n.index in ticked:
                readers.setdefault(name, set()).add(n.index)
    out = []
    for name, nodes in sorted(readers.items()):
        key = declared[name]
        live: set[int] = set()
        # per node, once: does its start clear the key (a scope it is within), does it
        # read it, write it (the monitor below asks for every transition of the graph)
        clears = frozenset(
            n.index
            for n in model.nodes
            if n.scope is not None and not key.lasting and key.scope.within(n.scope)
        )
        reads = frozenset(n.index for n in model.nodes if name in n.reads)
        writes = frozenset(n.index for n in model.nodes if name in n.writes)

        def bit(
            step: Step,
            on: bool,
            live: set[int] = live,
            clears: frozenset[int] = clears,
            reads: frozenset[int] = reads,
            writes: frozenset[int] = writes,
        ) -> tuple[bool, int | None]:
            for i, started in step.ticked:
                if started and i in clears:
                    on = False
                if on and i in reads:
                    live.add(i)
                if i in writes:
                    on = True
            return on, None

        monitor(graph, bit)
        for dead in sorted(nodes - live):
            run = monitor(graph, _reaching(dead))
            if run is not None:
                run.note = (
                    f"{model.nodes[dead].label()} reads {name}, which no run writes before it"
                )
                out.append(run)
    return out


def _reaching(node: int) -> Callable[[Step, bool], tuple[bool, int | None]]:
    """A monitor that stops at the first tick of ``node``."""

    def step_bit(step: Step, on: bool) -> tuple[bool, int | None]:
        return on, (node if any(i == node for i, _ in step.ticked) else None)

    return step_bit


def check_builtin(graph: Graph, model: Model, safety: Safety) -> dict[str, list[Broken]]:
    """Every built-in property: name -> what broke it (empty: it holds)."""
    runs: dict[str, list[Run]] = {name: [] for name in BUILT_IN}
    for name, run in safety.broken(graph).items():
        runs[name].append(run)
    for name, check in (
        ("ends-well", ends_well),
        ("bounded-retries", bounded_retries),
        ("home-obeyed", home_obeyed),
    ):
        if not runs[name]:
            found = check(graph, model)
            if found is not None:
                runs[name].append(found)
    runs["no-dead-reads"] = no_dead_reads(graph, model)
    return {name: [Broken(name, MEANING[name], r) for r in rs] for name, rs in runs.items()}


@dataclass(frozen=True, slots=True)
class Trigger:
    """How often a property's trigger was reached in the explored graph: ``count`` of
    ``what`` (states that saw a pause, retries, ...). Never reached: the property holds
    only because nothing ever asked it to, and verify says it is vacuous."""

    count: int
    what: str

    @property
    def vacuous(self) -> bool:
        return self.count == 0


def builtin_triggers(graph: Graph, model: Model) -> dict[str, Trigger]:
    """Each built-in property's trigger, counted over the explored states and ticks."""
    started = paused = home = out_of_service = driving = 0
    drives = [n.index for n in model.nodes if n.role is Role.DRIVE]
    for nodes, world in graph.states:
        started += bool(world[STARTED])
        paused += bool(world[PAUSED])
        home += bool(world[HOME])
        out_of_service += not world[IN_SERVICE]
        driving += any(nodes[i] > 0 and (nodes[i] - 1) & 1 for i in drives)
    retries = 0
    ticked: set[int] = set()
    for _, _, step in graph.each():
        retries += sum(kind is Event.RETRY for kind, _, _ in step.events)
        ticked.update(i for i, _ in step.ticked)
    declared = by_name()
    reads = sum(
        1
        for n in model.nodes
        if n.index in ticked
        for name in n.reads
        if (key := declared.get(name)) is not None and key.source is Source.LEAF
    )
    return {
        "ends-well": Trigger(started, "states with a tour under way"),
        "home-obeyed": Trigger(home, "states after home"),
        "service-off-obeyed": Trigger(out_of_service, "states out of service (service_off)"),
        "pause-obeyed": Trigger(paused, "states paused"),
        "no-content-while-driving": Trigger(driving, "states with a drive under way"),
        "bounded-retries": Trigger(retries, "retries"),
        "no-dead-reads": Trigger(reads, "reads of keys the tree writes, by nodes that run"),
    }
