"""The one base of leaves that send the robot a goal and wait for its answer.

As Nav2's ``BtActionNode``: send on start, poll on tick, cancel on halt. A subclass of
:class:`GoalLeaf` says how to send (:meth:`~GoalLeaf.send`), what else may hold the
sending back (:meth:`~GoalLeaf.hold`), its default timeout
(:meth:`~GoalLeaf.default_timeout`; the ``timeout`` parameter wins) and what to note
(:meth:`~GoalLeaf.succeeded`, :meth:`~GoalLeaf.failed`, :meth:`~GoalLeaf.progress`).
The base owns the rest:

* the command goes out through :meth:`~GoalLeaf.send_goal` only: in ``initialise``, or,
  while :meth:`~GoalLeaf.held` holds it (the operator's pause, ``/paused``, for a leaf
  that ``waits_while_paused``; then the subclass's own reason), on a later tick;
* a pause while the goal of such a leaf is out stops the robot at once: a goal at its
  own pose (``/pose``) replaces it, and the goal goes out again once the pause ends;
* a goal answered on ``/FROG_response`` is followed on ``/goal`` (:func:`goal_state`):
  SUCCESS on 2, FAILURE on 3 or 4 or once another goal replaced it. A command answered
  elsewhere (docking, on ``/docking``) overrides :meth:`~GoalLeaf.poll`;
* the timeout, on the project clock, from when the command went out;
* ``terminate`` on FAILURE or a halt: stop waiting for the goal, so that a late
  response to it is stale (:meth:`~frog_bt.engine.actions.Actions.cancel`; idempotent).
"""

from __future__ import annotations

import enum
from typing import ClassVar, Protocol

from pydantic import BaseModel

from frog_bt.model import keys
from frog_bt.model.goals import Goal
from frog_bt.model.ros import Pose
from frog_bt.model.wire import SUCCEEDED
from frog_bt.tree.leaf import FAILURE, INVALID, RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.node import NodeParams
from frog_bt.tree.world import Channel, World

__all__ = ["Failure", "GoalLeaf", "goal_state"]


def goal_state(sent: Goal, latest: Goal | None) -> Goal | None:
    """``sent`` as the board's ``/goal`` says it is now; None once a newer goal replaced
    it. Within the tick that sent it the board may still hold an older goal."""
    if latest is None or latest.id < sent.id:
        return sent
    return latest if latest.id == sent.id else None


class Failure(enum.Enum):
    """Why a goal leaf failed; the value is the word a note uses."""

    REFUSED = "refused"  # the robot answered failure (/FROG_response 3 or 4, docking failed)
    REPLACED = "replaced"  # a newer goal replaced it: one is pending at a time (CONTRACT §1)
    TIMED_OUT = "timed out"
    AWAY = "not at its place"  # asked where it cannot be done (dock away from the dock)


class TimedParams(NodeParams, Protocol):
    """A goal leaf's ``Params``: with a ``timeout`` (seconds, None: the default)."""

    @property
    def timeout(self) -> float | None: ...


class GoalLeaf(Leaf):
    """Base of the leaves that send a goal and wait for its answer (not a tree node).

    A subclass declares ``/now`` in ``reads``, ``/goal`` too unless it overrides
    :meth:`poll`, and ``/paused`` in ``optional_reads`` if it ``waits_while_paused``.
    Its ``Params`` has ``timeout`` (seconds, None: :meth:`default_timeout`).
    """

    waits_while_paused: ClassVar[bool] = False  # the operator's pause holds the sending
    params: TimedParams
    world = World(
        inputs=(Channel.GOAL, Channel.CLOCK),
        state=("goal", "latest", "sent_at", "timeout"),
        times=("sent_at",),
        timer=lambda n: n.sent_at + n.timeout if n.sent_at is not None else None,
        active="sent_at",
    )

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        declared = {k.name for k in (*cls.reads, *cls.optional_reads)}
        needed = {
            keys.NOW.name: True,
            keys.GOAL.name: cls.poll is GoalLeaf.poll,
            keys.PAUSED.name: cls.waits_while_paused,
            keys.POSE.name: cls.waits_while_paused,  # a pause stops the robot where it is
        }
        missing = [name for name, need in needed.items() if need and name not in declared]
        if missing:
            raise TypeError(f"{cls.__name__} reads {', '.join(missing)} without declaring it")

    def __init__(self, name: str, params: BaseModel | None = None) -> None:
        super().__init__(name, params)
        self.goal: Goal | None = None  # the goal sent, while one is followed on /goal
        self.latest: Goal | None = None  # it as /goal says it now; None once replaced
        self.sent_at: float | None = None  # project-clock time the command went out
        self.timeout = 0.0

    # what a subclass says

    def default_timeout(self) -> float:
        """Seconds before it fails when the ``timeout`` parameter is unset."""
        raise NotImplementedError

    def begin(self) -> None:
        """Work as the leaf starts, before the command may go out (read, write keys)."""

    def hold(self) -> str | None:
        """Why the command may not go out yet (the feedback), or None."""
        return None

    def paused_feedback(self) -> str:
        """The feedback while the operator's pause holds the command."""
        return f"paused: {self.name} waits"

    def send(self) -> Goal | None:
        """Send the command and note it; the goal to follow on ``/goal``, or None when
        :meth:`poll` reads the answer elsewhere."""
        raise NotImplementedError

    def poll(self) -> Status | Failure:
        """SUCCESS, RUNNING, or why it failed, from the answer so far. By default the
        answer is ``/goal``'s: the sent goal's response, or that a newer goal replaced
        it; :attr:`latest` is left as ``/goal`` says the goal is now."""
        assert self.goal is not None, "a goal leaf without poll() sends a Goal"
        self.latest = goal_state(self.goal, self.get(keys.GOAL))
        if self.latest is None:
            return Failure.REPLACED
        if self.latest.code == SUCCEEDED:
            return SUCCESS
        return Failure.REFUSED if self.latest.done else RUNNING

    def succeeded(self) -> None:
        """Note the success (called once, as it ends)."""

    def failed(self, why: Failure) -> None:
        """Note the failure and record what follows from it (called once, as it ends)."""

    def progress(self) -> str | None:
        """The feedback while it waits for the answer; None keeps the current one."""
        return None

    # what the base does

    def held(self) -> str | None:
        """Why the command may not go out now, or None: the one place a hold is
        decided. The operator's pause (``/paused``) holds a leaf that
        ``waits_while_paused``; then the subclass's :meth:`hold`."""
        if self.waits_while_paused and self.get(keys.PAUSED):
            return self.paused_feedback()
        return self.hold()

    def send_goal(self) -> None:
        """(Re)send the command: the one place it goes out. A goal sent again is a new
        goal, which replaces the one followed so far; the timeout runs from now."""
        now = self.ctx.clock.now()
        self.goal = self.send()
        self.latest = self.goal
        self.sent_at = self.goal.sent_at if self.goal is not None else now

    def _send_unless_held(self) -> bool:
        """Send the command unless it is held (the reason becomes the feedback); whether
        it is out."""
        reason = self.held()
        if reason is not None:
            self.feedback_message = reason
            return False
        self.send_goal()
        return True

    def initialise(self) -> None:
        self.goal = self.latest = None
        self.sent_at = None
        self.timeout = self.params.timeout or self.default_timeout()
        self.begin()
        self._send_unless_held()

    def _stop_for_pause(self) -> None:
        """The operator paused while the goal is out: stop the robot now (a goal at its own
        pose replaces this one) and forget the goal; :meth:`send_goal` sends it again once
        the pause ends."""
        self.ctx.actions.cancel(self.goal)
        reading = self.get(keys.POSE)
        if reading is not None:
            here = reading.value
            now = self.ctx.clock.now()
            self.ctx.actions.stop(Pose(now, "map", here.x, here.y, here.qz, here.qw))
            self.ctx.note(f"paused: stopped at ({here.x:.1f}, {here.y:.1f})")
        self.goal = self.latest = None
        self.sent_at = None

    def update(self) -> Status:
        if self.sent_at is not None and self.waits_while_paused and self.get(keys.PAUSED):
            self._stop_for_pause()
        if self.sent_at is None and not self._send_unless_held():
            return RUNNING
        assert self.sent_at is not None
        result = self.poll()
        if result is SUCCESS:
            self.succeeded()
            return SUCCESS
        if isinstance(result, Failure):
            self.failed(result)
            return FAILURE
        if self.need(keys.NOW) - self.sent_at >= self.timeout:
            self.failed(Failure.TIMED_OUT)
            return FAILURE
        feedback = self.progress()
        if feedback is not None:
            self.feedback_message = feedback
        return RUNNING

    def terminate(self, new_status: Status) -> None:
        if new_status in (INVALID, FAILURE):
            self.ctx.actions.cancel(self.goal)
