"""Telemetry of the executive for the rerun viewer: map, tree, status lanes, plots, log.

The only part of frog-bt that imports rerun, and only once a :class:`Telemetry`
is opened, so ``import frog_bt.live.telemetry`` is cheap and works without rerun::

    telemetry = Telemetry.open("save:tour.rrd", site, tree)
    telemetry.attach(host)      # taps on the core: cheap appends on the tick path
    ...                         # buffered rows are written in batches every 50 ticks
    telemetry.close()           # writes what is left and finishes the file

Modules: :mod:`.spec` (the ``--rerun`` value), :mod:`.layout` (tree numbering and
the graph's tidy layout), :mod:`.site_map` (POIs, routes, zones as geometry),
:mod:`.rows` (the taps), :mod:`.observer` (what both writers share), :mod:`.writer`
and :mod:`.blueprint` (rerun). What is
logged where: ``docs/TELEMETRY.md``.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Iterator
from typing import TYPE_CHECKING

from frog_bt.live.telemetry.layout import TreeIndex, tidy_layout
from frog_bt.live.telemetry.observer import TelemetryObserver
from frog_bt.live.telemetry.spec import Sink, parse_spec
from frog_bt.runtime import background

if TYPE_CHECKING:
    from rerun import RecordingStream

    from frog_bt.config import Site
    from frog_bt.model.links import LinkStatus
    from frog_bt.tree.loader import LoadedTree

__all__ = ["Sink", "Telemetry", "TreeIndex", "parse_spec", "tidy_layout"]
log = logging.getLogger(__name__)
BATCH_TICKS = 50  # rows are written every this many ticks (5 s at 10 Hz), and on flush()
CLOSE_TIMEOUT = 5.0  # seconds close() waits for the sink


class Telemetry(TelemetryObserver):
    """One rerun recording of one executive run (or replay). Build it with :meth:`open`."""

    def __init__(
        self, rec: RecordingStream, site: Site, tree: LoadedTree, *, batch_ticks: int = BATCH_TICKS
    ) -> None:
        """Log to ``rec`` (a ``rerun.RecordingStream`` with its sink already set)."""
        from frog_bt.live.telemetry.writer import Writer

        super().__init__(site, tree, batch_ticks=batch_ticks)
        self.rec = rec
        rec.set_log_time_enabled(False)  # only the tick and project-clock timelines
        rec.set_log_tick_enabled(False)
        self.writer = Writer(rec, site, self.index)
        self._writing: deque[tuple[int, Iterator[None]]] = deque()  # batches being written
        self.write_errors = 0  # batches that could not be written (logged, never raised)
        self.writer.write_static()  # with the default layout (a blueprint)

    @classmethod
    def open(
        cls,
        spec: str,
        site: Site,
        tree: LoadedTree,
        *,
        app_id: str = "frog-bt",
        recording_id: str | None = None,
    ) -> Telemetry:
        """A recording streaming to ``spec`` (see :mod:`frog_bt.live.telemetry.spec`).

        Raises ValueError for a spec it does not know, before anything starts.
        """
        sink = parse_spec(spec)
        import rerun as rr

        rec = rr.RecordingStream(app_id, recording_id=recording_id)
        if sink.kind == "save":
            rec.save(sink.target)
        elif sink.kind == "connect":
            rec.connect_grpc(sink.target)
        elif sink.kind == "serve":
            server = rr.GrpcServerSink(bind_ip="127.0.0.1", port=sink.port)
            rec.set_sinks(server)
            log.warning("rerun telemetry served at %s", server.uri)
        else:
            rec.spawn(port=sink.port)
        return cls(rec, site, tree)

    def _write_tree(self, tick: int, t: float, index: TreeIndex, generation: int) -> None:
        try:
            self.writer.reload(tick, t, index, generation)
        except Exception:  # telemetry must never stop the robot
            self.write_errors += 1
            log.exception("rerun telemetry: could not write the reloaded tree")

    def _write_links(self, tick: int, t: float, changes: list[tuple[str, LinkStatus]]) -> None:
        try:
            self.writer.write_links(tick, t, changes)
        except Exception:  # telemetry must never stop the robot
            self.write_errors += 1
            log.exception("rerun telemetry: could not write the links")

    def _flush_soon(self) -> None:
        """Write the rows in steps (:meth:`Writer.steps`), each a background job
        (:mod:`frog_bt.runtime.background`), so that an input arriving meanwhile waits for
        one step at most (a fraction of a millisecond), not for the whole batch."""
        self._flush_pending = False
        if self._closed:
            return
        batch = self.rows.drain()
        if len(batch):
            self._writing.append((len(batch), self.writer.steps(batch)))
            if len(self._writing) == 1:
                self._step()

    def _step(self) -> None:
        while self._writing and not self._next_step():
            pass
        if self._writing:
            # the next step at a quiet turn: what is due (an input, the tick it calls
            # for, the frames that tick sends) goes first
            background.soon(self._step)

    def _next_step(self) -> bool:
        """One step of the oldest batch being written; False when that batch is done."""
        rows, steps = self._writing[0]
        try:
            next(steps)
            return True
        except StopIteration:
            pass
        except Exception:  # telemetry must never stop the robot
            self.write_errors += 1
            log.exception("rerun telemetry: could not write %d rows", rows)
        self._writing.popleft()
        return False

    def flush(self) -> None:
        """Write the buffered rows to the recording now (and any batch still in steps)."""
        if self._closed:
            return
        while self._writing:
            self._next_step()
        batch = self.rows.drain()
        if len(batch):
            try:
                self.writer.write(batch)
            except Exception:  # telemetry must never stop the robot
                self.write_errors += 1
                log.exception("rerun telemetry: could not write %d rows", len(batch))

    def close(self) -> None:
        """Write what is left, then finish the file or disconnect. Idempotent."""
        if self._closed:
            return
        self.flush()
        self._closed = True
        self.rows.detach()
        try:  # bounded: a viewer that never answered must not hold the exit for ever
            self.rec.flush(timeout_sec=CLOSE_TIMEOUT)
        except Exception as exc:
            log.warning("rerun telemetry: %s", exc)
        self.rec.disconnect()
