"""Where the tour tree handles the operator's commands (:mod:`frog_bt.engine.operator`).

``home`` is ``MustAbort``'s business (the same polite abort as a low battery); ``pause``
holds ``Navigate`` and ``PlayContent`` before they start; the two below handle ``skip``
and ``service_off``.
"""

from __future__ import annotations

from collections.abc import Iterator

import py_trees

from frog_bt.behaviours.navigation import PoiParams
from frog_bt.behaviours.registry import register, register_decorator
from frog_bt.engine.observed import Role
from frog_bt.model import keys
from frog_bt.model.outcomes import IncidentKind
from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.world import Channel, World
from frog_bt.tree.world import Role as WorldRole


@register_decorator
class OperatorSkip(FrogDecorator):
    """A stop an operator may skip: leave it (or the drive to it) and go on with the next.

    Reads ``/skip`` (optional: the operator's skip requests this tour). When the count
    grows while the child runs, the child is stopped (content ends, navigation is
    cancelled, scopes switch off) and this returns SUCCESS, noting a ``stop left``
    incident; otherwise it returns the child's status.
    """

    Params = PoiParams
    params: PoiParams
    optional_reads = (keys.SKIP,)
    role = Role.STOP  # the core asks the running ones what a skip would leave
    _requested = False
    world = World(
        inputs=(Channel.OPERATOR,),
        state=("skips", "_requested"),
        counts=((keys.SKIP.name, "skips"),),
        why="of /skip it reads only how many skips came since it started",
    )

    def stop_poi(self) -> str:
        return self.params.poi

    def initialise(self) -> None:
        self.skips = self.get(keys.SKIP) or 0

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        # An asked-for skip: py_trees' plain behaviour tick (update says SUCCESS, stop
        # stops the child) instead of the decorator's, which would tick the child first.
        self._requested = self.status == RUNNING and (self.get(keys.SKIP) or 0) > self.skips
        if self._requested:
            yield from py_trees.behaviour.Behaviour.tick(self)
        else:
            yield from super().tick()

    def update(self) -> Status:
        if self._requested:
            self.ctx.note(
                f"skipped {self.params.poi}: the operator asked",
                incident=IncidentKind.STOP_LEFT,
                subject=self.params.poi,
            )
            return SUCCESS
        return self.decorated.status


@register
class WaitInService(Leaf):
    """Start no tour while the robot is out of service (``service_off``).

    Reads ``/in_service`` (optional: in service unless an operator said otherwise).
    RUNNING while out of service, else SUCCESS.
    """

    optional_reads = (keys.IN_SERVICE,)
    world = World(inputs=(Channel.OPERATOR,), waits=True, role=WorldRole.IDLE)

    def update(self) -> Status:
        if self.get(keys.IN_SERVICE) is False:
            self.feedback_message = "out of service: no tour starts"
            return RUNNING
        return SUCCESS
