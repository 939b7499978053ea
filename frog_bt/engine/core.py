"""The executive without I/O: inputs in, ticks, commands out.

:class:`Core` owns the inputs cache, the robot actions, the blackboard snapshot
and the py_trees tree. The online executive feeds it from rosbridge and UDP;
replay feeds it from a recording; tests feed it by hand. Outputs leave through
the two callbacks given to it (``publish(topic, msg)`` and ``send(message)``),
so the same tick code runs everywhere. What crosses it is told to ``emit`` as one
:data:`~frog_bt.model.events.Event` at a time (the host's observers hear it).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import msgspec
import py_trees

from frog_bt.clock import Clock
from frog_bt.config import Site
from frog_bt.engine import observed
from frog_bt.engine.actions import Actions
from frog_bt.engine.belief import Judgement
from frog_bt.engine.blackboard import Board, Inputs, Snapshot
from frog_bt.engine.context import Context
from frog_bt.engine.loaded import LoadedTree
from frog_bt.engine.observed import Observed, Role, Trace
from frog_bt.engine.operator import Answer, Command, Operator
from frog_bt.engine.standing import Standing
from frog_bt.model import keys
from frog_bt.model.events import (
    Blamed,
    Doubted,
    Event,
    Faulted,
    FrontendIn,
    FrontendOut,
    OperatorDone,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.frontend import FrontendMessage, Tour, UserNegative, UserPositive
from frog_bt.model.goals import Goal
from frog_bt.model.key import Reading
from frog_bt.model.outcomes import AbortReason, TourState
from frog_bt.model.wire import INPUTS, OUTPUTS
from frog_bt.warning_limit import WarningLimiter

log = logging.getLogger(__name__)
Status = py_trees.common.Status

Behaviour = py_trees.behaviour.Behaviour
Emit = Callable[[Event], None]
__all__ = ["Core", "Emit"]


class Core:
    def __init__(
        self,
        site: Site,
        tree: LoadedTree,
        clock: Clock,
        publish: Callable[[str, dict[str, Any], bool], None],
        send: Callable[[FrontendMessage], None],
        emit: Emit | None = None,
        standing: Standing | None = None,
        after_tick: Callable[[], None] | None = None,
        blame_first: bool = True,
    ) -> None:
        self.site = site
        self.tree = tree
        self.clock = clock
        self._publish_topic = publish
        self._send = send
        # The host's observers: a callable that is false while nobody listens (no event is
        # built then: a replay without observers pays nothing for them), or None.
        self.emit = emit
        # The host's own step after each tick, before the observers hear it (the executive
        # checks its alerts there: a tick's alert changes are recorded with the tick)
        self.after_tick = after_tick
        # The executive's state, kept across trees (a reload hands the next core the same)
        standing = self.standing = standing if standing is not None else Standing(clock)
        # Blame is worked out as a command goes out: before it where the host reads it in
        # its publish (a replay compares it), after it where the command must not wait
        # (the executive: ~20 µs per command off the way to the robot)
        self.blame_first = blame_first
        self.blamed = "-"  # the node that sent the latest command (see who())
        self.blamed_reads: dict[str, str] = {}  # what that node read, as short text
        self._labels: dict[int, str] = {}
        self.table = {site.topic(role): inp for role, inp in INPUTS.items()}
        if standing.inputs is None:
            standing.inputs = Inputs(self.table)
        self.inputs = standing.inputs  # what the robot last said still holds after a reload
        inputs = self.inputs
        self.actions = Actions(
            self._publish, clock, poses=lambda: inputs.poses, on_doubt=self._doubted
        )
        self.board = Board(standing.values)  # this core's own; the lasting keys the executive's
        self.trace = Trace()
        self.journal = standing.journal
        self.faults = standing.faults
        self.faults.emit = self._faulted
        self.ctx = Context(clock, site, self.actions, self._send_message, self.journal, self.faults)
        self.stray_answers = 0  # a visitor's answers that came with no question open
        self._warnings = WarningLimiter(logger=log)
        self._waiters: dict[type, list[py_trees.behaviour.Behaviour]] | None = None  # _awaited
        self.snapshot = Snapshot(
            self.board,
            self.inputs,
            clock,
            self.actions,
            believe=(
                site.navigation.tolerance,
                site.recruit.detection_max_age,
                site.navigation.pose_grace,
            ),
        )
        self.root = tree.root
        self.stops = [
            n for n in tree.root.iterate() if isinstance(n, Observed) and n.role is Role.STOP
        ]
        self.seekers = [n for n in tree.root.iterate() if getattr(n, "role", None) is Role.SEEK]
        self.operator = Operator(self.board, standing, self._stops_now, site.operator.pause_max)
        self.pause_ran_out: AbortReason | None = None  # set by the tick it happened before
        self.ticks = 0
        self._setup = False
        # Nodes ticked or stopped since the last tick's taps ran: every node whose status
        # changed is among them (a status changes only in its node's tick or in stop()),
        # so observers can follow the tree in O(active path) rather than O(tree).
        self.touched: list[Behaviour] = []
        self.told: list[Behaviour] = []  # the nodes the last tick touched, for its observers
        observed.attach(tree.root, self.touched)

    def who(self, node: Behaviour | None) -> str:
        """The node that sent a command, as people find it: its name and where it is
        written (``Navigate POI1 (goto.yaml:5)``); ``-`` for none (the executive)."""
        if node is None:
            return "-"
        label = self._labels.get(id(node))
        if label is None:
            where = self.tree.where.get(id(node))
            line = where.line if where else None
            place = f" ({Path(where.file).name}:{line[0]})" if where and line else ""
            label = self._labels[id(node)] = f"{node.name}{place}"
        return label

    def _note_sender(self) -> None:
        """Blame: the acting node, and what it and the nodes that decided for it read
        (those that ended earlier in this tick near it: up to three levels up, e.g. the
        engagement vote and its samples before ``PlayContent`` or ``FinishPoi``)."""
        node = self.trace.current()
        self.blamed = self.who(node)
        deciders = (
            [node, *reversed([d for d in self.trace.decided if d is not node and _near(d, node)])]
            if node is not None
            else []
        )
        reads: dict[str, str] = {}
        for decider in deciders:
            seen = (
                *getattr(decider, "reads", ()),
                *getattr(decider, "optional_reads", ()),
                *(getattr(decider, "writes", ()) if decider is not node else ()),
            )
            for key in seen:  # a decider's conclusions too (the engagement decision)
                if key is not keys.NOW and key.name not in reads:
                    reads[key.name] = _short(self.board.get(key))
        self.blamed_reads = reads

    def _publish(self, role: str, value: object, goal: Goal | None) -> None:
        topic = self.site.topic(role)
        msg = OUTPUTS[role].codec.encode(value)
        if self.blame_first:
            self._note_sender()
        self._publish_topic(topic, msg, goal is not None)  # a goal goes out at once
        if not self.blame_first:
            self._note_sender()
        emit = self.emit
        if emit:
            now = self.clock.now()
            emit(RobotCommand(now, role, topic, value, msg, goal))
            emit(Blamed(now, topic, self.blamed, self.blamed_reads))

    def _doubted(self, code: int, goal: Goal, judgement: Judgement) -> None:
        """An answer not believed: one log line, a journal note, the observers told."""
        log.warning("%s", judgement.why)
        self.journal.note(judgement.why)
        if self.emit:
            self.emit(
                Doubted(self.clock.now(), code, goal.target, judgement.why, judgement.answers)
            )

    def _faulted(self, event: Faulted) -> None:
        if self.emit:
            self.emit(event)

    def _send_message(self, message: FrontendMessage) -> None:
        if self.blame_first:
            self._note_sender()
        self._send(message)
        if not self.blame_first:
            self._note_sender()
        if isinstance(message, Tour) and message.state == TourState.STARTED:
            self.journal.tally.tour_started()
        emit = self.emit
        if emit:
            now = self.clock.now()
            emit(FrontendOut(now, message))
            emit(Blamed(now, message.type, self.blamed, self.blamed_reads))

    def setup(self) -> None:
        """Hand every node the context, this core's board and trace (py_trees' setup)."""
        if not self._setup:
            py_trees.trees.setup(self.root, ctx=self.ctx, board=self.board, trace=self.trace)
            self._setup = True

    # ------------------------------------------------------------ inputs (cache only)

    def on_ros(self, topic: str, value: object, raw: msgspec.Raw | None = None) -> bool:
        """Cache one decoded message (``value`` None: it did not decode, or the tree does
        not read its topic: told to the observers only); True when it calls for a tick."""
        now = self.clock.now()
        if self.emit:
            self.emit(RobotInput(now, topic, value, raw))
        inp = self.table.get(topic)
        if inp is None or value is None:
            return False
        self.inputs.add(inp, value, now)
        return inp.tick

    def on_event(self, message: FrontendMessage) -> None:
        """Queue a new front-end event for the next tick's snapshot."""
        now = self.clock.now()
        if isinstance(message, UserPositive | UserNegative) and not self._awaited(message):
            # Nobody asked: the tree would not read it, so no observer counts it either (a
            # late "yes" is no recruit); counted, noted and logged here instead.
            self._stray_answer(message)
            return
        if self.emit:
            self.emit(FrontendIn(now, message))
        self.inputs.events.append((message, now))

    def _awaited(self, message: FrontendMessage) -> bool:
        """Does a node wait for ``message``'s kind now? (It runs, and its ``world.frontend``
        names the kind: found once per tree, so an answer costs a few status reads.)"""
        if self._waiters is None:
            self._waiters = {}
            for node in self.root.iterate():
                waits = getattr(getattr(node, "world", None), "frontend", None)
                for kind in {type(m) for m in waits(node)} if waits is not None else ():
                    self._waiters.setdefault(kind, []).append(node)
        return any(n.status is Status.RUNNING for n in self._waiters.get(type(message), ()))

    def _stray_answer(self, message: FrontendMessage) -> None:
        """A visitor's answer nobody asked for now (after the answer timeout, or twice):
        neither the tree nor the observers get it; counted, noted, and logged (at most
        once per interval). The datagram itself is recorded as it came."""
        self.stray_answers += 1
        what = f"the visitor's {message.type} came with no question open: ignored"
        self.ctx.note(what)
        self._warnings.warn("stray answer", f"{what} ({self.stray_answers} so far)")

    # ------------------------------------------------------------ operator commands

    def stops_now(self) -> list[str]:
        """The stops being visited or driven to now (what a skip would leave)."""
        return self._stops_now()

    def _stops_now(self) -> list[str]:
        """The stops being visited or driven to now (what a skip would leave)."""
        return [n.stop_poi() for n in self.stops if n.status is Status.RUNNING]

    def command(self, command: Command, by: str = "") -> Answer:
        """Apply an operator command now: call it between ticks (it takes effect in the
        next one). The observers hear it, with its answer and who sent it (``by``)."""
        now = self.clock.now()
        answer = self.operator.apply(command, now)
        if self.emit:
            self.emit(
                OperatorDone(now, self.ticks + 1, command.value, answer.ok, answer.text, by=by)
            )
        return answer

    # ------------------------------------------------------------ ticking

    def tick(self) -> Status:
        """The pre-tick step (snapshot the inputs, apply the responses), one tick of the
        root, the host's ``after_tick``, then :class:`~frog_bt.model.events.Ticked` to the
        observers (they may read this core's tree, board and journal as the tick left
        them); the root's status."""
        self.setup()
        emit = self.emit
        settle = getattr(emit, "settle", None)
        if settle is not None:
            settle()  # the observers have heard the last tick's end before this one starts
        self.trace.decided.clear()
        self.pause_ran_out = self.operator.check_pause(self.clock.now())
        touched = self.touched
        try:
            self.snapshot.write()
            touched.extend(self.root.tick())  # stopped nodes are already in it
        except Exception as exc:  # a node's own failure is caught by the node (Declared.tick)
            self.faults.failed("the tree", exc, f"tick {self.ticks + 1}")
        self.ticks += 1
        status = self.root.status
        if self.after_tick is not None:
            self.after_tick()
        if emit:
            ticked = Ticked(self.clock.now(), self.ticks, status.name)  # type: ignore[arg-type]
            # told once the tick's callback is over (Observers.later): off the tick's path
            later = getattr(emit, "later", None)
            if later is not None:
                self.told = touched.copy()  # what the observers read as touched by it
                later(ticked)
            else:
                self.told = touched
                emit(ticked)
        touched.clear()
        return status

    def halt(self) -> None:
        """Stop whatever runs; scopes clean up (face stream off, ...)."""
        if self.root.status == Status.RUNNING:
            self.root.stop(Status.INVALID)

    @property
    def last_note(self) -> str:
        return self.journal.last_note


NEAR = 3  # levels above a command's sender within which a decider counts


def _near(decider: Behaviour, sender: Behaviour) -> bool:
    """Is ``decider`` within the subtree ``NEAR`` levels above ``sender``?"""
    top: Behaviour | None = sender
    for _ in range(NEAR):
        if top is None or top.parent is None:
            break
        top = top.parent
    up: Behaviour | None = decider
    while up is not None:
        if up is top:
            return True
        up = up.parent
    return False


def _short(value: Any) -> str:
    """A blackboard value as a short line of text (for a divergence report)."""
    if isinstance(value, Reading):
        value = value.value
    if isinstance(value, tuple) and value and hasattr(value[-1], "describe"):
        text = ": ".join([*map(str, value[:-1]), value[-1].describe()])
    else:
        text = value.describe() if hasattr(value, "describe") else repr(value)
    return text if len(text) <= 120 else text[:117] + "..."
