"""The face data stream and the engagement it measures (seed: "ICL FaceDataStream").

:class:`FaceStream` is a scope: ``/ICL_command start`` when entered, ``stop``
when left for any reason; while it runs it stores the qualifying face samples
and sends the engagement meter every ``engagement.window`` seconds.
:class:`DecideEngagement` takes the decision over the samples stored so far;
:class:`Engaged` tests it. The maths is in :mod:`frog_bt.maths.engagement`.
"""

from __future__ import annotations

from collections.abc import Iterator

import py_trees
from pydantic import Field

from frog_bt.frontend.messages import Engagement
from frog_bt.maths.engagement import Decision, Samples, decide, meter, qualifies
from frog_bt.tree.decorators import FrogDecorator, register_decorator
from frog_bt.tree.leaf import FAILURE, RUNNING, SUCCESS, Leaf, Params, Status, register


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

    reads = ("/faces", "/now")
    writes = ("/icl", "/engagement", "/engagement_meter")

    def provides(self) -> tuple[str, ...]:
        """What the child may read while the stream is on (the data-flow check)."""
        return self.writes

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour,
                 params: Params | None = None) -> None:
        super().__init__(name, child, params)
        self._on = False

    def initialise(self) -> None:
        self.ctx.actions.icl(True)
        self._on = True
        self.samples = Samples()
        self.last_face_data = self.ctx.clock.now()
        self.next_meter = self.ctx.clock.now() + self.ctx.site.engagement.window
        self.set("/icl", True)
        self.set("/engagement", self.samples)

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        # Store this tick's samples before the child runs, so a decision taken
        # in this tick counts every sample that arrived before it.
        if self._on and self.status == RUNNING:
            self._collect()
        yield from super().tick()

    def _collect(self) -> None:
        near = self.ctx.site.engagement.near
        faces = self.get("/faces", ())
        now = self.ctx.clock.now()
        if faces:
            self.last_face_data = now
        elif now - self.last_face_data > self.ctx.site.safety.face_silence:
            self.feedback_message = f"no face data for {now - self.last_face_data:.0f} s"
        for t, face in faces:
            if qualifies(face, near):
                self.samples.add(t, face.engagement)

    def update(self) -> Status:
        if self._on:
            window = self.ctx.site.engagement.window
            now = self.get("/now")
            while now >= self.next_meter:
                level = meter(self.samples.window(self.next_meter - window, self.next_meter))
                self.ctx.send(Engagement(level))
                self.set("/engagement_meter", level)
                self.next_meter += window
        return self.decorated.status

    def terminate(self, new_status: Status) -> None:
        if self._on:  # idempotent: py_trees may call terminate twice
            self._on = False
            self.ctx.actions.icl(False)
            self.set("/icl", False)


@register
class DecideEngagement(Leaf):
    """Decide whether the visitor is engaged, over the samples stored so far.

    Reads ``/engagement`` (optional: no session means no data). Writes
    ``/engaged`` (True, False, or None without face data) and
    ``/engagement_decision`` (the :class:`~frog_bt.maths.engagement.Decision`, with
    ``about`` for whom it was taken). SUCCESS.
    """

    class Params(Params):
        about: str = Field("", description="what the decision is about, for notes and "
                           "telemetry (the POI, or introduction)")

    optional_reads = ("/engagement",)
    writes = ("/engaged", "/engagement_decision")
    key_types = {"/engaged": bool | None, "/engagement_decision": tuple[str, Decision]}

    def update(self) -> Status:
        cfg = self.ctx.site.engagement
        samples: Samples | None = self.get("/engagement")
        levels = samples.levels() if samples is not None else Samples().levels()
        decision: Decision = decide(levels, cfg.edge, cfg.on_tie)
        self.set("/engaged", decision.engaged)
        self.set("/engagement_decision", (self.params.about, decision))
        self.ctx.note(f"{self.params.about or 'engagement'}: {decision.describe()}")
        return SUCCESS


@register
class Engaged(Leaf):
    """Is the visitor engaged? Reads ``/engaged``.

    SUCCESS when True, FAILURE when False; without face data (None), the site's
    ``engagement.no_data`` decides.
    """

    reads = ("/engaged",)
    key_types = {"/engaged": bool | None}

    def update(self) -> Status:
        engaged = self.get("/engaged")
        if engaged is None:
            engaged = self.ctx.site.engagement.no_data
        return SUCCESS if engaged else FAILURE
