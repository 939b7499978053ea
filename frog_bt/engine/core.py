"""The executive without I/O: inputs in, ticks, commands out.

:class:`Core` owns the inputs cache, the robot actions, the blackboard snapshot
and the py_trees tree. The online executive feeds it from rosbridge and UDP;
replay feeds it from a recording; tests feed it by hand. Outputs leave through
the two callbacks given to it (``publish(topic, msg)`` and ``send(message)``),
so the same tick code runs everywhere.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import py_trees

from frog_bt.clock import Clock
from frog_bt.config import Site
from frog_bt.engine import observed
from frog_bt.engine.actions import Actions
from frog_bt.engine.blackboard import Board, Inputs, Snapshot
from frog_bt.engine.context import Context
from frog_bt.engine.journal import Journal
from frog_bt.engine.loaded import LoadedTree
from frog_bt.engine.observed import Trace
from frog_bt.engine.operator import Answer, Command, Operator
from frog_bt.model import keys
from frog_bt.model.frontend import FrontendMessage
from frog_bt.model.goals import Goal
from frog_bt.model.key import Reading
from frog_bt.model.outcomes import AbortReason
from frog_bt.model.wire import INPUTS, OUTPUTS

log = logging.getLogger(__name__)
Status = py_trees.common.Status

Tap = Callable[[float, str, Any], None]  # (project-clock time, channel, payload)
Behaviour = py_trees.behaviour.Behaviour
__all__ = ["Core", "Outgoing", "Taps"]


@dataclass(frozen=True, slots=True)
class Outgoing:
    """One command to the robot: its output role and topic, the typed value, the
    ``msg`` dict sent, and the goal it carries (goto, approach; None for the others)."""

    role: str
    topic: str
    value: object
    msg: dict[str, Any]
    goal: Goal | None = None


@dataclass(slots=True)
class Taps:
    """Observers of what crosses the core (recording, telemetry, summaries, status line).

    ``ros_in`` gets typed values, ``ros_out`` each :class:`Outgoing` command,
    ``frontend_in`` and ``frontend_out`` typed front-end messages (channel = message
    type), ``tick`` the core after each tick. Taps must be quick: they run on the tick
    path.
    """

    ros_in: list[Tap] = field(default_factory=list)
    ros_out: list[Callable[[float, Outgoing], None]] = field(default_factory=list)
    frontend_in: list[Tap] = field(default_factory=list)
    frontend_out: list[Tap] = field(default_factory=list)
    tick: list[Callable[[Core], None]] = field(default_factory=list)
    blame: list[Tap] = field(default_factory=list)  # (t, channel, node, reads) after each command
    operator: list[Callable[[float, int, Command, Answer], None]] = field(
        default_factory=list)  # (t, tick it precedes, command, answer) for each command


class Core:
    def __init__(self, site: Site, tree: LoadedTree, clock: Clock,
                 publish: Callable[[str, dict[str, Any]], None],
                 send: Callable[[FrontendMessage], None]) -> None:
        self.site = site
        self.tree = tree
        self.clock = clock
        self._publish_topic = publish
        self._send = send
        self.taps = Taps()
        self.blamed = "-"  # the node that sent the latest command (see who())
        self.blamed_reads: dict[str, str] = {}  # what that node read, as short text
        self._labels: dict[int, str] = {}
        self.table = {site.topic(role): inp for role, inp in INPUTS.items()}
        self.inputs = Inputs(self.table)
        self.actions = Actions(self._publish, clock)
        self.board = Board()  # this core's own: nothing global, two cores in one process
        self.trace = Trace()
        self.journal = Journal(clock)
        self.ctx = Context(clock, site, self.actions, self._send_message, self.journal)
        self.snapshot = Snapshot(self.board, self.inputs, clock, self.actions)
        self.root = tree.root
        self._skippable = [n for n in tree.root.iterate() if getattr(n, "handles_skip", False)]
        self.operator = Operator(self.board, self.journal, self._stops_now,
                                 site.operator.pause_max)
        self.pause_ran_out: AbortReason | None = None  # set by the tick it happened before
        self.ticks = 0
        self._setup = False
        # Nodes ticked or stopped since the last tick's taps ran: every node whose status
        # changed is among them (a status changes only in its node's tick or in stop()),
        # so observers can follow the tree in O(active path) rather than O(tree).
        self.touched: list[Behaviour] = []
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
        deciders = [node, *reversed([d for d in self.trace.decided if d is not node
                                     and _near(d, node)])] if node is not None else []
        reads: dict[str, str] = {}
        for decider in deciders:
            seen = (*getattr(decider, "reads", ()), *getattr(decider, "optional_reads", ()),
                    *(getattr(decider, "writes", ()) if decider is not node else ()))
            for key in seen:  # a decider's conclusions too (the engagement decision)
                if key is not keys.NOW and key.name not in reads:
                    reads[key.name] = _short(self.board.get(key))
        self.blamed_reads = reads

    def _blame(self, channel: str) -> None:
        if self.taps.blame:
            now = self.clock.now()
            for tap in self.taps.blame:
                tap(now, channel, self.blamed, self.blamed_reads)

    def _publish(self, role: str, value: object, goal: Goal | None) -> None:
        topic = self.site.topic(role)
        self._note_sender()
        msg = OUTPUTS[role].codec.encode(value)
        self._publish_topic(topic, msg)
        if self.taps.ros_out:
            out = Outgoing(role, topic, value, msg, goal)
            for tap in self.taps.ros_out:
                tap(self.clock.now(), out)
        self._blame(topic)

    def _send_message(self, message: FrontendMessage) -> None:
        self._note_sender()
        self._send(message)
        for tap in self.taps.frontend_out:
            tap(self.clock.now(), message.type, message)
        self._blame(message.type)

    def setup(self) -> None:
        """Hand every node the context, this core's board and trace (py_trees' setup)."""
        if not self._setup:
            py_trees.trees.setup(self.root, ctx=self.ctx, board=self.board, trace=self.trace)
            self._setup = True

    # ------------------------------------------------------------ inputs (cache only)

    def on_ros(self, topic: str, value: Any) -> bool:
        """Cache one decoded message; True when it calls for a tick."""
        now = self.clock.now()
        for tap in self.taps.ros_in:
            tap(now, topic, value)
        inp = self.table.get(topic)
        if inp is None:
            return False
        self.inputs.add(inp, value, now)
        return inp.tick

    def on_event(self, message: FrontendMessage) -> None:
        now = self.clock.now()
        for tap in self.taps.frontend_in:
            tap(now, message.type, message)
        self.inputs.events.append((message, now))

    # ------------------------------------------------------------ operator commands

    def _stops_now(self) -> list[str]:
        """The stops being visited or driven to now (what a skip would leave)."""
        return [n.params.poi for n in self._skippable  # type: ignore[attr-defined]
                if n.status == Status.RUNNING]

    def command(self, command: Command) -> Answer:
        """Apply an operator command now: call it between ticks (it takes effect in the
        next one). The operator taps hear it, with its answer."""
        now = self.clock.now()
        answer = self.operator.apply(command, now)
        for tap in self.taps.operator:
            tap(now, self.ticks + 1, command, answer)
        return answer

    # ------------------------------------------------------------ ticking

    def tick(self) -> Status:
        """The pre-tick step (snapshot the inputs, apply the responses), one tick of the
        root, the tick taps; the root's status."""
        self.setup()
        self.trace.decided.clear()
        self.pause_ran_out = self.operator.check_pause(self.clock.now())
        self.snapshot.write()
        touched = self.touched
        touched.extend(self.root.tick())  # stopped nodes are already in it
        self.ticks += 1
        for tap in self.taps.tick:
            tap(self)
        touched.clear()
        return self.root.status

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
