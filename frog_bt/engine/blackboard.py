"""One executive's blackboard, the inputs cache, and the pre-tick snapshot onto it.

Subscriber callbacks only *cache* (:class:`Inputs`); once per tick,
:meth:`Snapshot.write` copies one consistent view onto the :class:`Board`, so no
input can change half-way through a tick (the py_trees_ros pattern). Each executive
owns its board: nothing is global, so two executives live in one process.

The keys and their types are declared in :mod:`frog_bt.model.keys`; the snapshot
writes the :attr:`~frog_bt.model.key.Source.INPUT` ones.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, TypeVar

from frog_bt.clock import Clock
from frog_bt.engine.actions import Actions
from frog_bt.engine.belief import World
from frog_bt.model import keys
from frog_bt.model.eventlog import EventLog
from frog_bt.model.frontend import FrontendIdle, FrontendMessage
from frog_bt.model.key import Key, Readable, Reading, Scope
from frog_bt.model.wire import Input, Keep

T = TypeVar("T")


class Board:
    """Typed keys to values; a key never written (or cleared) reads as None, and
    :meth:`written` tells it from one written as None (no data).

    A :attr:`~frog_bt.model.key.Key.lasting` key is kept in ``lasting``, a store the
    executive owns (:class:`~frog_bt.engine.standing.Standing`): the next core's board,
    after a reload, reads the same values."""

    def __init__(self, lasting: dict[Key[Any], Any] | None = None) -> None:
        self._values: dict[Key[Any], Any] = {}
        self._lasting: dict[Key[Any], Any] = lasting if lasting is not None else {}

    def _store(self, key: Key[Any]) -> dict[Key[Any], Any]:
        return self._lasting if key.lasting else self._values

    def get(self, key: Readable[T]) -> T | None:
        assert isinstance(key, Key)  # the one kind of Readable
        value: T | None = self._store(key).get(key)  # the store holds every key's type
        return value

    def set(self, key: Key[T], value: T | None) -> None:
        self._store(key)[key] = value

    def written(self, key: Key[Any]) -> bool:
        """Has ``key`` a value of this scope (None included)?"""
        return key in self._store(key)

    def clear_scope(self, scope: Scope) -> list[Key[Any]]:
        """Forget every value that ends when ``scope`` starts; the keys that had one."""
        gone = [k for k in self._values if k.scope.within(scope)]
        for key in gone:
            del self._values[key]
        return gone

    def items(self) -> Iterator[tuple[Key[Any], Any]]:
        """Every key written so far, with its value (observers: telemetry, blame)."""
        return iter([*self._lasting.items(), *self._values.items()])


class Inputs:
    """Latest inputs as the callbacks leave them; touched only by callbacks and snapshot.

    ``table`` maps each topic name to its :class:`~frog_bt.model.wire.Input`."""

    def __init__(self, table: dict[str, Input]) -> None:
        self.table = table
        self.latest: dict[Key[Any], Reading[Any] | None] = {
            i.key: None for i in table.values() if i.keep is Keep.LATEST
        }
        self.pending: dict[Key[Any], list[tuple[Any, ...]]] = {
            i.key: [] for i in table.values() if i.keep is not Keep.LATEST
        }
        self.events: list[tuple[FrontendMessage, float]] = []
        self.poses = 0  # /FROG_pose messages received so far: the order of the robot's answers

    def add(self, inp: Input, value: Any, at: float) -> None:
        """Cache one decoded message of ``inp``. A queued one (``/FROG_response``) keeps
        how many poses had arrived before it (:mod:`frog_bt.engine.belief`: order)."""
        if inp.keep is Keep.LATEST:
            self.latest[inp.key] = Reading(value, at)
            if inp.key is keys.POSE:
                self.poses += 1
            return
        pending = self.pending[inp.key]
        if inp.keep is Keep.SAMPLES:
            assert inp.items is not None
            pending.extend((at, item) for item in inp.items(value))
        else:
            pending.append((value, at, self.poses))
        if len(pending) > inp.limit:
            del pending[: len(pending) - inp.limit]  # a stalled tick must not grow memory


class Snapshot:
    """Writes the input keys once per tick (the pre-tick step): the clock, the latest
    inputs, the front end's events, and the newest goal with the responses applied."""

    def __init__(
        self,
        board: Board,
        inputs: Inputs,
        clock: Clock,
        actions: Actions,
        believe: tuple[float, float, float] | None = None,
    ) -> None:
        self.board = board
        self.inputs = inputs
        self.clock = clock
        self.actions = actions
        # (navigation.tolerance, recruit.detection_max_age, navigation.pose_grace): judge
        # the robot's answers
        self.believe = believe
        events = board.get(keys.EVENTS)  # the executive's, kept across trees
        self.events = events if events is not None else EventLog()
        if not board.written(keys.FRONTEND_READY):
            board.set(keys.FRONTEND_READY, False)
        self.write()

    def write(self) -> None:
        inp, set_ = self.inputs, self.board.set
        set_(keys.NOW, self.clock.now())
        for key, reading in inp.latest.items():
            set_(key, reading)
        for key, pending in inp.pending.items():
            set_(key, tuple(pending))
            pending.clear()
        if inp.events:
            for message, at in inp.events:
                self.events.append(message, at)
                if isinstance(message, FrontendIdle):
                    set_(keys.FRONTEND_READY, True)
            inp.events.clear()
        set_(keys.EVENTS, self.events)
        actions, believe = self.actions, self.believe
        for code, at, poses in self.board.get(keys.RESPONSES) or ():
            actions.on_response(code, at, self._world(poses))
        if believe is not None and actions.unconfirmed is not None:
            world = self._world(self.inputs.poses)
            assert world is not None
            actions.confirm(world, believe[2])
        set_(keys.GOAL, self.actions.latest)

    def _world(self, poses: int) -> World | None:
        """What the robot says besides its answers, as the judge sees it (None: answers
        are not judged), ``poses`` the poses received before the answer."""
        believe, board = self.believe, self.board
        if believe is None:
            return None
        return World(
            now=board.get(keys.NOW) or 0.0,
            pose=board.get(keys.POSE),
            persons=board.get(keys.PERSONS),
            poses_at_answer=poses,
            tolerance=believe[0],
            detection_max_age=believe[1],
        )
