"""The explorer: the real tree (the loader's nodes in a real
:class:`~frog_bt.engine.core.Core`) ticked, with only the world abstracted.

A :class:`Real` holds one core (a :class:`~frog_bt.clock.ManualClock`, the outputs
captured: the seam the tests use). From a state it restores every node and the engine,
sets the world's inputs for one tick from the explorer's choices, ticks the real root
once and reads what the nodes did: their statuses, the commands they published and sent,
the board. Composites, decorators, operator commands (:meth:`Core.command`), guards and
each leaf's own ``update()`` run as in production.

What no leaf can know is chosen per tick from a finite set (:mod:`frog_bt.tree.world`:
each node type declares its world interface on its class): the operator's command, a
wait running out, the robot's answer to the pending goal (a pose at the goal with an
arrival; the camera seeing the visitor with an approach's success), the docking state,
the front end's events; and, as a node reads them, the diagnostics, nobody or someone
new facing the robot, someone following, a face. Every combination is explored (an
:class:`~frog_bt.verify.explore.Oracle` replays a prefix of choices; each choice beyond it
branches).

The project clock never moves: a wait runs out by its own times moving back
(``World.fire``), so a wait is pending or run out, and which of several runs out first
is a choice. A state is what the nodes hold (each running node's declared fields, a
composite's current child, a retry's count) with the board's live values, the pending
goal and the world; its canonical encoding (:meth:`Real.key`) keeps of each what some
outcome depends on, as the classes declare it (``ignores``, ``truthy``, ``views``,
``counts``, ``people``: ids only as whether the current visitor's; ``places``: where the
robot is only as whether at a waypoint a node compares with), event indexes relative to
the newest event and goal ids to the newest goal, so that alike states hash alike. Each
new state is kept as a snapshot (per node, its ``__dict__``; the engine's stores),
restored before each tick from it.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import logging
import math
import operator
import time
from collections import deque
from collections.abc import Callable, Hashable, Iterator
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import py_trees

from frog_bt.clock import ManualClock
from frog_bt.config import Site
from frog_bt.engine.core import Core
from frog_bt.engine.loaded import LoadedTree
from frog_bt.engine.operator import Command
from frog_bt.maths.engagement import Samples
from frog_bt.model import keys
from frog_bt.model.eventlog import EventLog
from frog_bt.model.events import Event as CoreEvent
from frog_bt.model.events import FrontendOut, RobotCommand
from frog_bt.model.frontend import AskTour, StartIntroduction, StartPoi, Tour
from frog_bt.model.goals import Goal
from frog_bt.model.help import HelpAbout
from frog_bt.model.key import Key, Reading
from frog_bt.model.outcomes import DockingState, TourState
from frog_bt.model.progress import Progress, Resume
from frog_bt.model.ros import (
    Diagnostics,
    Face,
    PersonDetection,
    PersonDetections,
    Point,
    Pose,
    TrackedPeople,
    TrackedPerson,
)
from frog_bt.model.wire import FAILED, SUCCEEDED
from frog_bt.tree.world import Channel, World, world_of
from frog_bt.verify.explore import MAX_STATES, Choice, Graph, Oracle, Step, TooBig
from frog_bt.verify.liveness import Liveness
from frog_bt.verify.model import Model, preorder
from frog_bt.verify.world import By
from frog_bt.verify.world import Event as VEvent

Behaviour = py_trees.behaviour.Behaviour
RUNNING = py_trees.common.Status.RUNNING
MORNING = 1780302600.0  # 2026-06-01 10:30 Europe/Madrid: the morning's waypoints
AWAY = (-1000.0, -1000.0)  # where a robot whose drive failed is: near no waypoint
STOP_HERE = "(stop here)"  # the goal that stops the robot where it is (not a drive)
# what py_trees and the engine change on every node (not the node type's own state)
INTERNAL = frozenset({"status", "feedback_message", "iterator"})
LAZY = (keys.DIAGNOSTICS, keys.PERSONS, keys.PEOPLE, keys.FACES)  # answered as read
DIAGNOSTICS = ("ok", "battery low", "fault")  # what a reader tells apart unless it says
TIME = 1e9  # a float this large is a project-clock time (encoded relative to now)


class Pruned(Exception):
    """A choice that changes nothing (a command the operator refuses): not explored."""


@dataclass(slots=True)
class Robot:
    """The world's own state: where the robot is (a waypoint, or None: away), its
    docking state, and whether the way home was reached since ``home``."""

    where: str | None
    docking: DockingState = DockingState.DOCKED
    homing: bool = False
    people: int = 0  # the persons the camera has shown so far (the next one is new)
    seen: int | None = None  # the visitor the camera sees as an approach succeeds
    reported: bool = True  # its docking state heard since the executive started

    def key(self, near: Callable[[str | None], Hashable]) -> tuple[object, ...]:
        """Its encoding; ``near``: where it is, as the nodes tell places apart."""
        return (near(self.where), self.docking, self.homing, self.reported)


@dataclass(slots=True)
class Saved:
    """A state: each node's ``__dict__`` (shared between states while unchanged) and the
    engine's stores."""

    nodes: tuple[dict[str, Any], ...]
    engine: tuple[Any, ...]
    running: list[int]  # the running nodes (pre-order)


@dataclass(slots=True)
class Found:
    """What verify found wrong with the node types while it explored."""

    undeclared: dict[str, set[str]] = field(default_factory=dict)  # class -> fields
    failed: list[str] = field(default_factory=list)  # a node's code raised


def _declared(world: World | None) -> frozenset[str]:
    return frozenset(world.state) if world is not None else frozenset()


class Real:
    """One core over ``tree`` (built by the loader), explored state by state."""

    def __init__(self, tree: LoadedTree, site: Site) -> None:
        self.site = site
        self.tree = tree
        self.clock = ManualClock(MORNING)
        self.events: list[tuple[VEvent, int, tuple[object, ...]]] = []
        self.touched: list[Behaviour] = []
        self.core = Core(
            site,
            tree,
            self.clock,
            lambda topic, msg, urgent: None,
            lambda message: None,
            emit=self._heard,
            after_tick=self._after_tick,
        )
        self.core.journal.limit = 16  # kept small: it is copied with every state
        self.core.setup()
        self.nodes = preorder(tree.root)
        self.index = {id(n): i for i, n in enumerate(self.nodes)}
        self.worlds = [world_of(type(n)) for n in self.nodes]
        self.declared = [_declared(w) | INTERNAL for w in self.worlds]
        # per node, what gives its undeclared fields (to compare them at once)
        self.watch: list[Callable[[dict[str, Any]], object] | None] = [None] * len(self.nodes)
        # the board's keys that hold people's ids (``World.people``; a node's own fields
        # are named there too)
        self.people = {name for w in self.worlds if w is not None for name in w.people}
        self.approaches = [i for i, w in enumerate(self.worlds) if _role(w) == "approach"]
        # keys every reader of which decides only on a view of the value (``World.views``)
        viewed: dict[str, dict[type, Callable[[Any], Hashable]]] = {}
        for n, w in zip(self.nodes, self.worlds, strict=True):
            for name, view in w.views if w is not None else ():
                viewed.setdefault(name, {})[type(n)] = view
        self.views = {
            name: list(by_type.values())
            for name, by_type in viewed.items()
            if all(
                type(n) in by_type
                for n in self.nodes
                for k in (*getattr(n, "reads", ()), *getattr(n, "optional_reads", ()))
                if k.name == name
            )
        }
        # counts on the board every reader of which reads only as a count since it began
        counted: dict[str, set[int]] = {}
        for i, w in enumerate(self.worlds):
            for name, _ in w.counts if w is not None else ():
                counted.setdefault(name, set()).add(i)
        self.counted = {
            name
            for name, counters in counted.items()
            if all(
                i in counters
                for i, n in enumerate(self.nodes)
                for k in (*getattr(n, "reads", ()), *getattr(n, "optional_reads", ()))
                if k.name == name
            )
        }
        self.copies = [i for i, w in enumerate(self.worlds) if w is not None and w.copy]
        self.retries = [
            i for i, n in enumerate(self.nodes) if isinstance(n, py_trees.decorators.Retry)
        ]
        self.dock = site.tour.dock
        self.robot = Robot(self.dock)
        # the waypoints some node compares the robot's pose with (``World.places``)
        self.places = sorted(
            {
                p
                for n, w in zip(self.nodes, self.worlds, strict=True)
                if w and w.places
                for p in w.places(n)
            }
        )
        self._nearness: dict[str | None, Hashable] = {}
        # the keys some node or the operator reads: a value nothing reads is not state;
        # an input the snapshot writes anew before every tick is the world's (derived)
        derived: set[Key[Any]] = {inp.key for inp in self.core.table.values()}
        derived |= {keys.NOW, keys.EVENTS}
        derived |= {keys.GOAL, keys.RESPONSES, *LAZY}
        self.liveness = Liveness(tree, self.nodes, self.index, derived)
        self.oracle = Oracle(())
        self.step = Step()
        self.asked: dict[str, object] = {}
        self.found = Found()
        self.live: list[dict[str, Any] | None] = [None] * len(self.nodes)
        self._running: list[int] | None = None
        self._board_get = self.core.board.get
        self.core.board.get = self._get  # type: ignore[method-assign]
        self._blaming = False
        note_sender = self.core._note_sender

        def blame() -> None:  # what a node read, for the record: no choice of the world
            self._blaming = True
            try:
                note_sender()
            finally:
                self._blaming = False

        self.core._note_sender = blame  # type: ignore[method-assign]
        self._publish_world(moved=True)
        self._canonical()
        self.initial = self.save()

    # ------------------------------------------------------------ the world answers

    def _choose(self, node: int, what: str, options: list[tuple[str, By]]) -> str:
        if len(options) == 1:
            return options[0][0]
        value, by = options[self.oracle.pick(len(options))]
        self.step.choices.append(Choice(node, what, value, by))
        return value

    def _near(self, where: str | None) -> Hashable:
        """Where the robot is as the nodes tell places apart: for each waypoint some node
        compares its pose with, whether it is within ``navigation.tolerance`` of it."""
        found = self._nearness.get(where)
        if found is None:
            x, y = AWAY if where is None else (self.site.pois[where].x, self.site.pois[where].y)
            tolerance = self.site.navigation.tolerance
            found = self._nearness[where] = tuple(
                math.hypot(x - self.site.pois[p].x, y - self.site.pois[p].y) <= tolerance
                for p in self.places
            )
        return found

    def _here(self) -> tuple[float, float]:
        if self.robot.where is None:
            return AWAY
        poi = self.site.pois[self.robot.where]
        return poi.x, poi.y

    def _get(self, key: Any) -> Any:
        """The board's value; for an input the world answers as it is read (once per
        tick, the same for every reader), a choice of the explorer."""
        if key not in LAZY:
            return self._board_get(key)
        if key in self.asked:
            return self.asked[key]
        reader = self.core.trace.current()
        if reader is None or self._blaming:  # judging an answer, or blaming: as it is
            return self._board_get(key)
        value = self.asked[key] = self._ask(key, reader)
        return value

    def _ask(self, key: Key[Any], reader: Behaviour) -> object:
        now = self.clock.now()
        x, y = self._here()
        at = self.index.get(id(reader), -1)
        if key is keys.DIAGNOSTICS:
            low = self.site.safety.battery_low - 5.0
            w = self.worlds[at] if at >= 0 else None
            told = w.diagnostics if w is not None else DIAGNOSTICS
            how = self._choose(
                -1, "diagnostics", [(d, By.QUIET if d == "ok" else By.WORLD) for d in told]
            )
            battery, faults = (low, ()) if how == "battery low" else (100.0, ())
            if how == "fault":
                faults = ("motors: fault",)  # type: ignore[assignment]
            return Reading(Diagnostics(now, battery, faults), now)
        if key is keys.PERSONS:
            # someone the robot has not seen before: a person it saw again is either
            # passed over (as if nobody) or, after renaming, alike a new one
            who = self._choose(
                at, "camera", [("nobody", By.QUIET), ("someone new faces it", By.WORLD)]
            )
            if who == "nobody":
                return Reading(PersonDetections(now, ()), now)
            self.robot.people += 1
            person = PersonDetection(self.robot.people, Point(x + 1.0, y), 180.0)
            return Reading(PersonDetections(now, (person,)), now)
        if key is keys.PEOPLE:
            near = self._choose(at, "visitor", [("nobody near", By.WORLD), ("follows", By.WORLD)])
            people = (TrackedPerson(1, Point(x, y)),) if near == "follows" else ()
            return Reading(TrackedPeople(now, people), now)
        # faces: one sample per stream, engaged or not, or none (a stream collects before
        # it ticks: the reader is the node above it)
        streams = [
            self.nodes[i]
            for i in self.running()
            if (w := self.worlds[i]) is not None and Channel.FACES in w.inputs
        ]
        if any(len(getattr(s, "samples", ())) for s in streams):
            return ()
        face = self._choose(
            at, "face", [("no face", By.QUIET), ("engaged", By.WORLD), ("not engaged", By.WORLD)]
        )
        if face == "no face":
            return ()
        level = 0.8 if face == "engaged" else -0.8
        return ((now, Face(1, level, 0.5, True)),)

    def _publish_world(self, moved: bool) -> None:
        """The robot's pose and docking state, fresh at this tick."""
        now = self.clock.now()
        x, y = self._here()
        inputs = self.core.inputs
        pose = Pose(now, "map", x, y, 0.0, 1.0)
        if moved:  # a new pose message: the answers after it may count on it
            self.core.on_ros(self.site.topic("pose"), pose)
        else:  # the same pose, repeated
            inputs.latest[keys.POSE] = Reading(pose, now)
        if self.robot.reported:
            inputs.latest[keys.DOCKING] = Reading(self.robot.docking, now)
        else:  # a restarted executive has not heard it yet
            inputs.latest.pop(keys.DOCKING, None)

    # ------------------------------------------------------------ what the tree did

    def _heard(self, event: CoreEvent) -> None:
        kind: VEvent | None = None
        if isinstance(event, RobotCommand):
            if event.role == "goto":
                goal = event.goal
                kind = VEvent.DRIVE if goal is None or goal.target != STOP_HERE else None
            elif event.role == "approach":
                kind = VEvent.APPROACH
            elif event.role == "dock":
                kind = VEvent.DOCK if event.value == "dock" else VEvent.UNDOCK
        elif isinstance(event, FrontendOut):
            message = event.message
            if isinstance(message, StartPoi):
                kind = VEvent.CONTENT
            elif isinstance(message, StartIntroduction | AskTour):
                kind = VEvent.SPEAK
            elif isinstance(message, Tour) and message.state is TourState.STARTED:
                kind = VEvent.TOUR_STARTED
        if kind is None:
            return
        node = self.core.trace.current()
        at = self.index.get(id(node), 0) if node is not None else 0
        self.events.append((kind, at, self.world_view()))
        if kind is VEvent.DRIVE and isinstance(event, RobotCommand) and event.goal is not None:
            self._drove_to = event.goal.target
        self._sent.append(kind)

    def _after_tick(self) -> None:
        self.touched = list(dict.fromkeys(self.core.touched))

    # ------------------------------------------------------------ snapshot and restore

    def save(self, parent: Saved | None = None, touched: list[int] | None = None) -> Saved:
        memo: dict[int, Any] = {}
        if parent is None:
            nodes = [dict(n.__dict__) for n in self.nodes]
            changed: list[int] = list(range(len(self.nodes)))
        else:
            nodes = list(parent.nodes)
            changed = [*(touched or ()), *self.copies]
            for i in changed:
                nodes[i] = dict(self.nodes[i].__dict__)
        for i in self.copies:
            w = self.worlds[i]
            assert w is not None
            for f in w.copy:
                if f in nodes[i]:
                    nodes[i][f] = _clone(nodes[i][f], memo)
        for i in changed:
            self.live[i] = None  # the live dict holds live objects: restore it next time
        core = self.core
        actions = core.actions
        journal = core.journal
        engine = (
            {k: _clone(v, memo) for k, v in core.board._values.items()},
            {k: _clone(v, memo) for k, v in core.standing.values.items()},
            core.standing.paused_since,
            dict(core.inputs.latest),
            core.inputs.poses,
            actions.snapshot(),
            (
                list(journal.notes),
                list(journal.incidents),
                journal.incident_total,
                copy.copy(journal.tally.by_kind),
                list(journal.tally.tour),
            ),
            self.clock.now(),
            core.pause_ran_out,
            (
                self.robot.where,
                self.robot.docking,
                self.robot.homing,
                self.robot.people,
                None,
                self.robot.reported,
            ),
        )
        return Saved(tuple(nodes), engine, self.running())

    def restore(self, saved: Saved) -> None:
        self._running = saved.running
        memo: dict[int, Any] = {}
        for i, node in enumerate(self.nodes):
            target = saved.nodes[i]
            if self.live[i] is not target:
                d = node.__dict__
                d.clear()
                d.update(target)
                self.live[i] = target
        for i in self.copies:
            w = self.worlds[i]
            assert w is not None
            d = self.nodes[i].__dict__
            for f in w.copy:
                if f in d:
                    d[f] = _clone(d[f], memo)
            self.live[i] = None
        (
            values,
            lasting,
            paused_since,
            latest,
            poses,
            goals,
            journal,
            now,
            pause_ran_out,
            robot,
        ) = saved.engine
        core = self.core
        board = core.board
        board._values = {k: _clone(v, memo) for k, v in values.items()}
        core.standing.values.clear()
        core.standing.values.update({k: _clone(v, memo) for k, v in lasting.items()})
        events = self._board_get(keys.EVENTS)
        assert events is not None  # the snapshot writes it before the first tick
        core.snapshot.events = events
        core.standing.paused_since = paused_since
        inputs = core.inputs
        inputs.latest = dict(latest)
        inputs.poses = poses
        for pending in inputs.pending.values():
            pending.clear()
        inputs.events.clear()
        core.actions.restore(goals)
        j = core.journal
        j.notes, j.incidents = list(journal[0]), list(journal[1])
        j.incident_total = journal[2]
        j.tally.by_kind = copy.copy(journal[3])
        j.tally.tour = list(journal[4])
        self.clock._now = now
        core.pause_ran_out = pause_ran_out
        self.robot = Robot(*robot)

    # ------------------------------------------------------------ one tick

    def positions(self) -> tuple[tuple[int, int], ...]:
        """The running nodes, each with its current child's position (-1: none)."""
        out = []
        for i in self.running():
            node = self.nodes[i]
            current = getattr(node, "current_child", None)
            at = -1
            if current is not None:
                at = next((k for k, c in enumerate(node.children) if c is current), -1)
            out.append((i, at))
        return tuple(out)

    def running(self) -> list[int]:
        """The running nodes, pre-order (kept until a tick or a restore changes them)."""
        found = self._running
        if found is None:
            found = self._running = [i for i, n in enumerate(self.nodes) if n.status is RUNNING]
        return found

    def tick(self, oracle: Oracle) -> Step:
        """One tick from the restored state, with ``oracle``'s choices."""
        core, board = self.core, self.core.board
        self.oracle = oracle
        self.fired: list[int] = []
        self.timed = False  # a wait's time was running as the tick began
        self.asked = {}
        self.events = []
        self._sent: list[VEvent] = []
        self._drove_to = ""
        self._heard_late = False
        step = self.step = Step(started_tour=board.get(keys.TOUR_STATE) is TourState.STARTED)
        help_before = board.get(keys.HELP) is not None
        running = self.running()
        moved = self._before(running)
        self._publish_world(moved)
        faults = core.faults.total
        self._running = None
        core.tick()
        self._running = None
        if self._heard_late:
            self.robot.reported = True  # heard before the next tick
        if core.faults.total != faults:
            for seen in core.faults.seen.values():
                line = f"{seen.where}: {seen.error}"
                if line not in self.found.failed:
                    self.found.failed.append(line)
        step.events = self.events
        self._after(step, help_before)
        self._canonical()
        return step

    def _canonical(self) -> None:
        """The interval since the last approach, pending whenever no approach runs: all
        a later approach may see is that it has to wait (until the explorer lets the
        interval run out) or not, and waiting first covers both."""
        if not any(self.nodes[i].status is RUNNING for i in self.approaches):
            self.core.actions.last_approach_at = self.clock.now()

    def _before(self, running: list[int]) -> bool:
        """The operator's command, a wait running out, or the world's answers: the
        inputs of this tick. Whether the robot moved (a new pose)."""
        core, board, robot = self.core, self.core.board, self.robot
        if not robot.reported:
            # a restart: the robot's docking state comes in the first tick or the next,
            # whatever else happens (well within ``checkpoint.confirm``: what
            # ConfirmResume waits for is there before it gives up)
            how = self._choose(-1, "robot", [("reports", By.ROBOT), ("not heard yet", By.ROBOT)])
            robot.reported = how == "reports"  # published before the tree ticks
            self._heard_late = not robot.reported
        options: list[tuple[str, By]] = [("none", By.QUIET)]
        touring = board.get(keys.TOUR_STATE) is TourState.STARTED
        ending = board.get(keys.HOME) is not None or board.get(keys.ABORT_REASON) is not None
        paused = bool(board.get(keys.PAUSED))
        if touring and not ending:
            options.append(("home", By.WORLD))
            if core.stops_now():
                options.append(("skip", By.WORLD))
        if paused:
            options.append(("resume", By.WORLD))
        elif touring:
            options.append(("pause", By.WORLD))
        in_service = board.get(keys.IN_SERVICE) is not False
        options.append(("service_off" if in_service else "service_on", By.WORLD))
        helping = board.get(keys.HELP)
        if helping is not None and board.get(keys.HELP_ANSWER) is None:
            options += [("retry", By.WORLD), ("done_by_hand", By.WORLD)]
        timers = self._timers(running, paused)
        self.timed = bool(timers)
        options += [(label, By.ROBOT) for label in timers]
        what = self._choose(-1, "operator", options)
        if what == "none":
            return self._answers(running)
        if what in timers:
            timers[what]()
            return False
        if what == "done_by_hand" and helping is not None:  # a person did the step
            if helping.about is HelpAbout.UNDOCK:
                robot.docking = DockingState.UNDOCKED
            elif helping.about is not HelpAbout.FAULT:
                robot.docking, robot.where = DockingState.DOCKED, self.dock
            self._publish_world(moved=True)
            # and the robot said so before the operator answered: the board has it (the
            # operator checks done_by_hand against the robot's docking state there)
            reported = core.inputs.latest.get(keys.DOCKING)
            if reported is not None:
                board.set(keys.DOCKING, reported)
        answer = core.command(Command(what))
        if not answer.ok:
            raise Pruned(what)
        return False

    def _timers(self, running: list[int], paused: bool) -> dict[str, Callable[[], None]]:
        """The waits still ahead, each with what makes it run out now. The clock never
        moves: a wait runs out by its own times moving back (``World.fire``), so that
        the others stay pending; which runs out first is the explorer's choice."""
        now = self.clock.now()
        out: dict[str, Callable[[], None]] = {}
        for i in running:
            w = self.worlds[i]
            if w is None or w.timer is None:
                continue
            due = w.timer(self.nodes[i])
            if due is not None and due > now:
                label = _timer_label(self.nodes, i)
                out[label if label not in out else f"{label} ({i})"] = partial(
                    self._fire, i, w, due - now
                )
        standing = self.core.standing
        since = standing.paused_since
        if paused and since is not None:
            left = since + self.core.operator.pause_max - now
            if left > 0:

                def pause_runs_out() -> None:
                    assert standing.paused_since is not None
                    standing.paused_since -= left

                out[_timer_label(self.nodes, -1)] = pause_runs_out
        return out

    def _fire(self, i: int, world: World, seconds: float) -> None:
        """Node ``i``'s wait runs out now: its ``fire``, or its ``times`` moved back."""
        node = self.nodes[i]
        self.fired.append(i)
        if world.fire is not None:
            world.fire(node, seconds)
            return
        for name in world.times:
            value = getattr(node, name, None)
            if value is not None:
                setattr(node, name, value - seconds)

    def _answers(self, running: list[int]) -> bool:
        """The robot answers its pending goal, the docking the running Docking asked
        for; the front end may send one of the events the running leaves wait for."""
        core, robot = self.core, self.robot
        moved = False
        goal = core.actions.pending
        if goal is not None:
            if goal.kind == "goto":
                how = self._choose(-1, "robot", [("arrives", By.ROBOT), ("fails", By.ROBOT)])
                if how == "arrives":
                    if goal.target != STOP_HERE:
                        robot.where = goal.target
                        moved = True
                else:
                    robot.where, moved = None, True
            else:
                how = self._choose(-1, "robot", [("reaches", By.ROBOT), ("fails", By.ROBOT)])
                robot.seen = int(goal.target) if how == "reaches" else None
            if moved:
                self._publish_world(moved=True)
            if robot.seen is not None:
                x, y = self._here()
                now = self.clock.now()
                seen = PersonDetections(now, (PersonDetection(robot.seen, Point(x, y), 180.0),))
                core.inputs.latest[keys.PERSONS] = Reading(seen, now)
            code = SUCCEEDED if how in ("arrives", "reaches") else FAILED
            core.on_ros(self.site.topic("response"), int(code))
        messages: list[Any] = []
        for i in running:
            node, w = self.nodes[i], self.worlds[i]
            if w is None:
                continue
            if w.frontend is not None:
                messages += [m for m in w.frontend(node) if m not in messages]
            if w.docking is not None:
                self._docking(i, w.docking(node))
        if not running:  # the first tick: the front end may have spoken before it
            for node, w in zip(self.nodes, self.worlds, strict=True):
                if w is not None and w.frontend is not None:
                    messages += [m for m in w.frontend(node) if m not in messages]
        if messages:
            options = [("none", By.QUIET), *((m.type, By.WORLD) for m in messages)]
            sent = self._choose(-1, "front end", options)
            for m in messages:
                if m.type == sent:
                    core.on_event(m)
                    break
        return moved

    def _docking(self, i: int, states: tuple[str, ...]) -> None:
        """A running node that asked the robot to dock or undock: the robot reports one of
        the states its type declares (``World.docking``)."""
        if states:
            how = self._choose(i, "docking", [(s, By.ROBOT) for s in states])
            self.robot.docking = DockingState(how)

    def _after(self, step: Step, help_before: bool) -> None:
        board = self.core.board
        step.ticked = []
        for node in self.touched:
            i = self.index[id(node)]
            started = i not in self.was_running
            if node.status is not py_trees.common.Status.INVALID or started:
                step.ticked.append((i, started))
        if board.get(keys.HELP) is not None and not help_before:
            asking = next((i for i in self.running() if _role(self.worlds[i]) == "help"), 0)
            step.events.append((VEvent.HELP, asking, self.world_view()))
        for i in self.retries:
            retry: Any = self.nodes[i]
            was = self.was_failures.get(i, 0)
            if retry.status is RUNNING and retry.failures > was:
                step.events.append((VEvent.RETRY, i, self.world_view()))
        if board.get(keys.HOME) is None:
            self.robot.homing = False
        elif (
            self._drove_to in (self.dock, *self.site.variants.get(self.dock, ()))
            or VEvent.DOCK in self._sent
            or any(k is VEvent.HELP for k, _, _ in step.events)
        ):
            self.robot.homing = True
        for i in self.running():
            w = self.worlds[i]
            if w is not None and w.waits:
                step.waits.append((i, "waits for a person or the front end"))
        if board.get(keys.PAUSED):
            step.waits.append((0, "paused: waits for resume"))

    def check_declared(self, saved: Saved) -> None:
        """Each node touched in the last tick: a field it changed that its type does not
        declare is reported by class."""
        for node in self.touched:
            i = self.index[id(node)]
            before, now = saved.nodes[i], node.__dict__
            watch = self.watch[i]
            if watch is not None and now.keys() == before.keys() and watch(now) == watch(before):
                continue  # no field it does not declare changed (compared at C speed)
            undeclared = [name for name in now if name not in self.declared[i]]
            self.watch[i] = operator.itemgetter(*undeclared) if undeclared else _nothing
            for name in undeclared:
                value = now[name]
                if name not in before or (before[name] is not value and before[name] != value):
                    self.found.undeclared.setdefault(type(node).__name__, set()).add(name)

    # ------------------------------------------------------------ what properties see

    def world_view(self) -> tuple[object, ...]:
        """The world as the properties read it (:mod:`frog_bt.verify.world`)."""
        get = self._board_get
        return (
            get(keys.TOUR_STATE) is TourState.STARTED,
            get(keys.ABORT_REASON) is not None,
            get(keys.HOME) is not None,
            bool(get(keys.PAUSED)),
            get(keys.IN_SERVICE) is not False,
            self.robot.docking is DockingState.DOCKED,
            get(keys.SKIPPED),
            self.robot.homing,
        )

    def view(self) -> tuple[tuple[int, ...], tuple[object, ...]]:
        """(per node: 0 not running, 1 running, 2 running with its action out; the world)."""
        out = []
        for n, w in zip(self.nodes, self.worlds, strict=True):
            if n.status is not RUNNING:
                out.append(0)
            elif w is not None and w.active and getattr(n, w.active, None) not in (None, False):
                out.append(2)
            else:
                out.append(1)
        return tuple(out), self.world_view()

    def key(self) -> Hashable:
        """The state's canonical encoding: alike states hash alike."""
        now = self.clock.now()
        core = self.core
        log: EventLog = core.snapshot.events
        last = log.last_index
        latest = core.actions.latest
        base = latest.id if latest is not None else 0
        poses = core.inputs.poses
        followed = {getattr(self.nodes[i], "goal", None) for i in self.running()} | {
            core.actions.pending
        }
        enc = _Encoder(
            now,
            base,
            poses,
            {g.id for g in followed if isinstance(g, Goal)},
            self._board_get(keys.VISITOR),
        )
        nodes: list[object] = []
        oldest = last
        since: dict[str, int] = {}  # a count's value as a running node that counts it began
        for i in self.running():
            node, w = self.nodes[i], self.worlds[i]
            if w is None:
                nodes.append(i)
                continue
            for name, at in w.counts:
                since[name] = getattr(node, at, None) or 0
            if w.key is not None:
                nodes.append((i, w.key(node)))
                continue
            fields: list[Hashable] = []
            for name in w.state:
                if name in w.ignores:
                    continue
                value = getattr(node, name, None)
                if name in w.indexes and isinstance(value, int):
                    oldest = min(oldest, value)
                    fields.append(value - last)
                elif name in w.people:
                    fields.append(enc.person(value))
                elif any(name == at for _, at in w.counts):
                    continue  # with the count on the board: the count since it began
                else:
                    fields.append(enc(value))
            nodes.append((i, tuple(fields)))
        live, presence = self.liveness.live(
            self.positions(), self._board_get(keys.RESUME) is not None
        )
        truthy = self.liveness.truthy
        board: list[tuple[str, Hashable]] = []
        for store in (core.board._values, core.standing.values):
            for k, v in store.items():
                # a value of None reads as none written; an unset truthy key reads false
                if v is None or (k not in live and k not in presence) or (k in truthy and not v):
                    continue
                if k in truthy:
                    board.append((k.name, True))
                elif k not in live:
                    board.append((k.name, True))  # only whether it is set
                elif k.name in since:  # unset, or none since it began: left out alike
                    if v != since[k.name]:
                        board.append((k.name, v - since[k.name]))
                elif k.name in self.counted:
                    continue  # read only as a count since a node starts: none runs
                elif k.name in self.views:
                    seen = tuple(view(v) for view in self.views[k.name])
                    board.append((k.name, enc.person(seen) if k.name in self.people else enc(seen)))
                elif k.name in self.people:
                    board.append((k.name, enc.person(v)))
                else:
                    board.append((k.name, enc(v)))
        board.sort(key=lambda e: e[0])
        tail = tuple(e.message for e in log.since(oldest)) if oldest < last else ()
        actions = core.actions
        engine = (
            enc(actions.pending),
            enc(latest),
            # the goal the pending one replaced while open: what a stale answer answers
            enc(actions.before) if actions.pending is not None else None,
            enc(actions.unconfirmed),
            enc(core.standing.paused_since),
            min(round(now - actions.last_approach_at, 3), self.site.recruit.approach_interval),
        )
        return (tuple(nodes), tuple(board), tail, engine, self.robot.key(self._near))

    # ------------------------------------------------------------ successors

    def successors(self, saved: Saved) -> Iterator[tuple[Callable[[], Saved], Step]]:
        """Every next state with the tick that led there (all choices enumerated): what
        saves it (to call before the next one; a state already seen need not be)."""
        pending: list[list[int]] = [[]]
        while pending:
            prefix = pending.pop()
            self.restore(saved)
            self.was_running = set(self.running())
            self.was_failures = {
                i: getattr(self.nodes[i], "failures", 0)
                for i in self.retries
                if i in self.was_running
            }
            oracle = Oracle(prefix)
            try:
                step = self.tick(oracle)
                ok = True
            except Pruned:
                ok = False
            if ok:
                self.check_declared(saved)
                touched = [*{self.index[id(n)]: None for n in self.touched}, *self.fired]
                for i in touched:
                    self.live[i] = None  # changed: restore it next time
                yield partial(self.save, saved, touched), step
            for k in range(len(prefix), len(oracle.widths)):
                for alt in range(1, oracle.widths[k]):
                    pending.append([*oracle.taken[:k], alt])

    def resumed(self, progress: Progress, docked: bool) -> Saved:
        """A start state of a restarted executive: the fresh start with ``progress`` as
        the checkpoint to resume (``/resume``, as the executive sets it), the robot away
        from the dock (``docked``: on its charger), its docking state not heard yet (it
        comes in the first tick or the second: ``ConfirmResume`` may wait for it)."""
        self.restore(self.initial)
        self.core.board.set(
            keys.RESUME, Resume(frozenset(progress.done), progress.visitor, progress.done)
        )
        if docked:
            self.robot = Robot(self.dock, reported=False)
        else:
            self.robot = Robot(None, DockingState.UNDOCKED, reported=False)
        self._publish_world(moved=True)
        return self.save()


class _Encoder:
    """A value, hashable, with project-clock times relative to now, goal ids relative to
    the newest goal; a goal no running node follows (and not pending) only as whether it
    is done (all that the next goal's belief reads of it)."""

    def __init__(
        self, now: float, base: int, poses: int, followed: set[int], visitor: int | None
    ) -> None:
        self.now, self.base, self.poses, self.followed = now, base, poses, followed
        self.visitor = visitor

    def person(self, value: Any) -> Hashable:
        """A value holding people's ids (``World.people``): each id only as whether it is
        the current visitor's (``/visitor``): people are alike."""
        if isinstance(value, int) and not isinstance(value, bool):
            return value == self.visitor
        if isinstance(value, frozenset | set):
            return frozenset(self.person(v) for v in value)
        if isinstance(value, tuple | list):
            return tuple(self.person(v) for v in value)
        if isinstance(value, dict):
            return frozenset((self.person(k), self(v)) for k, v in value.items())
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            return tuple(self.person(getattr(value, f.name)) for f in dataclasses.fields(value))
        return self(value)

    def __call__(self, value: Any) -> Hashable:
        if value is None or isinstance(value, bool | int | str | enum.Enum):
            return value
        if isinstance(value, float):
            return round(value - self.now, 3) if value > TIME else round(value, 3)
        if isinstance(value, Goal):
            if value.id not in self.followed:
                return ("goal", value.done)
            target: Hashable = value.target
            if value.kind == "approach":  # a person's id
                target = value.target.isdigit() and int(value.target) == self.visitor
            return (
                value.kind,
                target,
                value.code,
                value.acknowledged,
                value.id - self.base,
                self(value.sent_at),
                value.poses == self.poses,  # no pose since it went out (belief: order)
            )
        if isinstance(value, Reading):
            return self(value.value)
        if isinstance(value, Pose):
            return (round(value.x, 2), round(value.y, 2))
        if isinstance(value, Samples):
            return value.levels()
        if isinstance(value, tuple | list | deque):
            return tuple(self(v) for v in value)
        if isinstance(value, frozenset | set):
            return frozenset(self(v) for v in value)
        if isinstance(value, dict):
            return tuple(sorted((self(k), self(v)) for k, v in value.items()))
        if isinstance(value, Behaviour):
            return value.name
        if dataclasses.is_dataclass(value):
            return tuple(self(getattr(value, f.name)) for f in dataclasses.fields(value))
        try:
            hash(value)
        except TypeError:
            return repr(value)
        return value  # type: ignore[no-any-return]


# the types whose values a tick never changes in place (learnt as met)
_SAME: set[type] = {type(None), bool, int, float, str, tuple, frozenset}


def _clone(value: Any, memo: dict[int, Any]) -> Any:
    """A copy of a mutable value a tick may change in place (one copy per object in a
    snapshot: the stream's samples are the board's); an immutable one as it is."""
    kind = type(value)
    if kind in _SAME:
        return value
    found = memo.get(id(value))
    if found is not None:
        return found
    out: Any
    if isinstance(value, EventLog):
        out = EventLog.__new__(EventLog)
        out._events = deque(value._events, maxlen=value._events.maxlen)
        out.last_index = value.last_index
    elif isinstance(value, Samples):
        out = Samples()
        out._t, out._level = list(value._t), list(value._level)
    elif isinstance(value, deque):
        out = deque(value, maxlen=value.maxlen)
    elif isinstance(value, dict | list | set):
        out = copy.copy(value)
    elif dataclasses.is_dataclass(value) and getattr(value, "__hash__", None) is not None:
        _SAME.add(kind)  # frozen
        return value
    elif isinstance(value, enum.Enum | bool | int | float | str | tuple | frozenset):
        _SAME.add(kind)
        return value
    elif hasattr(value, "__dict__"):  # one level deeper: its lists and dicts copied
        out = copy.copy(value)
        out.__dict__.update({k: _clone(v, memo) for k, v in value.__dict__.items()})
    else:
        return value
    memo[id(value)] = out
    return out


def _nothing(_: object) -> None:
    return None


def _timer_label(nodes: list[Behaviour], i: int) -> str:
    return "time: the pause runs out" if i < 0 else f"time: {nodes[i].name} runs out"


def _role(world: World | None) -> str:
    return world.role.value if world is not None else ""


def explore(
    model: Model,
    site: Site,
    on_step: Callable[[int, Step, int, Any], None] | None = None,
    limit: int = MAX_STATES,
    restarts: bool = True,
) -> tuple[Graph, Found]:
    """Every reachable state of the real tree, breadth-first from a fresh start and, with
    ``restarts``, from every checkpoint the tree wrote (a restarted executive's start)."""
    started = time.perf_counter()
    logging.disable(logging.WARNING)  # a doubted answer is logged once per tick: quiet
    try:
        return _explore(model, site, on_step, limit, restarts, started)
    finally:
        logging.disable(logging.NOTSET)


def _explore(
    model: Model,
    site: Site,
    on_step: Callable[[int, Step, int, Any], None] | None,
    limit: int,
    restarts: bool,
    started: float,
) -> tuple[Graph, Found]:
    real = Real(model.tree, site)
    graph = Graph(model, [real.view()], [(-1, -1)], [])
    saved = [real.initial]
    index: dict[Hashable, int] = {real.key(): 0}
    progresses: dict[Progress, None] = {}

    def run(head: int) -> int:
        while head < len(graph.states):
            edges: list[tuple[int, Step]] = []
            graph.edges.append(edges)
            for save, step in real.successors(saved[head]):
                key = real.key()
                dst = index.get(key)
                if dst is None:
                    dst = len(graph.states)
                    if dst >= limit:
                        raise TooBig(f"more than {limit} states")
                    index[key] = dst
                    graph.states.append(real.view())
                    graph.parent.append((head, len(edges)))
                    saved.append(save())
                    progress = real.core.board.get(keys.PROGRESS)
                    if progress is not None and progress.done:
                        progresses[progress] = None
                if (
                    dst == head
                    and real.timed
                    and not any(c.value.startswith("time:") for c in step.choices)
                ):
                    # nothing changed while a wait's time runs: time passes (the explorer
                    # lets it run out as a choice of its own), no loop of the robot's
                    step.waits.append((-1, "waits for its time to run out"))
                edges.append((dst, step))
                if on_step is not None:
                    on_step(head, step, dst, graph.states[dst])
            head += 1
        return head

    head = run(0)
    if restarts:
        for progress in list(progresses):
            for docked in (False, True):
                start = real.resumed(progress, docked)
                key = real.key()
                if key in index:
                    continue
                index[key] = len(graph.states)
                graph.starts.append(len(graph.states))
                graph.states.append(real.view())
                graph.parent.append((-1, -1))
                saved.append(start)
        run(head)
    graph.seconds = time.perf_counter() - started
    return graph, real.found
