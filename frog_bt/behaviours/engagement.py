"""The face data stream and the engagement it measures (seed: "ICL FaceDataStream").

:class:`FaceStream` is a scope: ``/ICL_command start`` when entered, ``stop``
when left for any reason; while it runs it stores the qualifying face samples
and sends the engagement meter every ``engagement.window`` seconds.
:class:`DecideEngagement` takes the decision over the samples stored so far;
:class:`Engaged` tests it. The maths is in :mod:`frog_bt.maths.engagement`.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import py_trees
from pydantic import Field

from frog_bt.behaviours.registry import register, register_decorator
from frog_bt.maths.engagement import Decision, Samples, decide, meter, qualifies
from frog_bt.model import keys
from frog_bt.model.frontend import Engagement
from frog_bt.tree.decorators import FrogDecorator
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status
from frog_bt.tree.world import Channel, World


@register_decorator
class FaceStream(FrogDecorator):
    """Face data stream on while the child runs, with engagement samples and meter.

    Sends ``/ICL_command`` start on entry and stop on exit (success, failure or
    interruption). While running, stores each face of ``/faces`` that is near
    (``engagement.near``) and facing, and every ``engagement.window`` seconds
    sends ``engagement`` with the meter level (null for an empty window).
    Reads ``/faces``, ``/now``; writes ``/icl`` (True while on),
    ``/engagement`` (the session's :class:`~frog_bt.maths.engagement.Samples`) and
    ``/engagement_meter``.
    Returns the child's status.
    """

    reads = (keys.FACES, keys.NOW)
    writes = (keys.ICL, keys.ENGAGEMENT, keys.ENGAGEMENT_METER)
    world = World(
        inputs=(Channel.FACES,),
        state=("samples", "last_face_data", "next_meter"),
        times=("last_face_data", "next_meter"),
        copy=("samples",),
        passes=True,
        key=lambda n: n.samples.levels(),
        why="engagement: one face sample per stream, engaged or not, or none; the vote "
        "over many samples is the maths' own (tests/maths). When the meter is sent "
        "changes what it says, not what the tree decides",
    )

    def provides(self) -> tuple[keys.Key[Any], ...]:
        """What the child may read while the stream is on (the data-flow check)."""
        return self.writes

    def _on(self) -> bool:
        """Is the stream on? (``/icl``: the one place this is kept.)"""
        return self._bb is not None and bool(self.get(keys.ICL))

    def initialise(self) -> None:
        self.ctx.actions.icl(True)
        self.samples = Samples()
        self.last_face_data = self.ctx.clock.now()
        self.next_meter = self.ctx.clock.now() + self.ctx.site.engagement.window
        self.set(keys.ICL, True)
        self.set(keys.ENGAGEMENT, self.samples)

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        # Store this tick's samples before the child runs, so a decision taken
        # in this tick counts every sample that arrived before it.
        if self.status == RUNNING and self._on():
            self._collect()
        yield from super().tick()

    def _collect(self) -> None:
        near = self.ctx.site.engagement.near
        faces = self.get(keys.FACES) or ()
        now = self.ctx.clock.now()
        if faces:
            self.last_face_data = now
        elif now - self.last_face_data > self.ctx.site.safety.face_silence:
            self.feedback_message = f"no face data for {now - self.last_face_data:.0f} s"
        for t, face in faces:
            if qualifies(face, near):
                self.samples.add(t, face.engagement)

    def update(self) -> Status:
        if self._on():
            window = self.ctx.site.engagement.window
            now = self.need(keys.NOW)
            while now >= self.next_meter:
                level = meter(self.samples.window(self.next_meter - window, self.next_meter))
                self.ctx.send(Engagement(level))
                self.set(keys.ENGAGEMENT_METER, level)
                self.next_meter += window
        return self.decorated.status

    def terminate(self, new_status: Status) -> None:
        if self._on():  # idempotent: py_trees may call terminate twice
            self.ctx.actions.icl(False)
            self.set(keys.ICL, False)


@register
class DecideEngagement(Leaf):
    """Decide whether the visitor is engaged, over the samples stored so far.

    Reads ``/engagement`` (optional: no session means no data). Writes
    ``/engaged`` (True, False, or None without face data) and
    ``/engagement_decision`` (the :class:`~frog_bt.maths.engagement.Decision`, with
    ``about`` for whom it was taken). SUCCESS.
    """

    class Params(Params):
        about: str = Field(
            "",
            description="what the decision is about, for notes and "
            "telemetry (the POI, or introduction)",
        )

    params: Params
    optional_reads = (keys.ENGAGEMENT,)
    writes = (keys.ENGAGED, keys.ENGAGEMENT_DECISION)
    world = World(sets=(keys.ENGAGED.name, keys.ENGAGEMENT_DECISION.name))

    def update(self) -> Status:
        cfg = self.ctx.site.engagement
        samples = self.get(keys.ENGAGEMENT)
        levels = samples.levels() if samples is not None else Samples().levels()
        decision: Decision = decide(levels, cfg.edge, cfg.on_tie)
        self.set(keys.ENGAGED, decision.engaged)
        self.set(keys.ENGAGEMENT_DECISION, (self.params.about, decision))
        self.ctx.note(f"{self.params.about or 'engagement'}: {decision.describe()}")
        return SUCCESS


@register
class Engaged(Leaf):
    """Is the visitor engaged? Reads ``/engaged``.

    SUCCESS when True, FAILURE when False; without face data (None), the site's
    ``engagement.no_data`` decides.
    """

    reads = (keys.ENGAGED,)
    world = World()

    def update(self) -> Status:
        engaged = self.get(keys.ENGAGED)
        if engaged is None:
            engaged = self.ctx.site.engagement.no_data
        return SUCCESS if engaged else FAILURE
