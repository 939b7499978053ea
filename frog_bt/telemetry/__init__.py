"""Telemetry of the executive for the rerun viewer: map, tree, status lanes, plots, log.

The only part of frog-bt that imports rerun, and only once a :class:`Telemetry`
is opened, so ``import frog_bt.telemetry`` is cheap and works without rerun::

    telemetry = Telemetry.open("save:tour.rrd", site, tree)
    telemetry.attach(core)      # taps on the core: cheap appends on the tick path
    ...                         # buffered rows are written in batches every 50 ticks
    telemetry.close()           # writes what is left and finishes the file

Modules: :mod:`.spec` (the ``--rerun`` value), :mod:`.layout` (tree numbering and
the graph's tidy layout), :mod:`.site_map` (POIs, routes, zones as geometry),
:mod:`.rows` (the taps), :mod:`.writer` and :mod:`.blueprint` (rerun). What is
logged where: ``docs/TELEMETRY.md``.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from frog_bt.telemetry.layout import TreeIndex, tidy_layout
from frog_bt.telemetry.rows import Rows
from frog_bt.telemetry.spec import Sink, parse_spec

if TYPE_CHECKING:
    from frog_bt.config import Site
    from frog_bt.core import Core
    from frog_bt.tree.loader import LoadedTree

__all__ = ["Sink", "Telemetry", "TreeIndex", "parse_spec", "tidy_layout"]
log = logging.getLogger(__name__)
BATCH_TICKS = 50  # rows are written every this many ticks (5 s at 10 Hz), and on flush()
CLOSE_TIMEOUT = 5.0  # seconds close() waits for the sink


class Telemetry:
    """One rerun recording of one executive run. Build it with :meth:`open`."""

    def __init__(self, rec: Any, site: Site, tree: LoadedTree, *,
                 batch_ticks: int = BATCH_TICKS) -> None:
        """Log to ``rec`` (a ``rerun.RecordingStream`` with its sink already set)."""
        from frog_bt.telemetry.blueprint import default_blueprint
        from frog_bt.telemetry.writer import Writer

        self.rec = rec
        rec.set_log_time_enabled(False)  # only the tick and project-clock timelines
        rec.set_log_tick_enabled(False)
        self.index = TreeIndex.of(tree.root)
        self.rows = Rows(site, self.index, batch_ticks=batch_ticks, on_full=self.flush)
        self.writer = Writer(rec, site, self.index)
        self._closed = False
        self.write_errors = 0  # batches that could not be written (logged, never raised)
        rec.send_blueprint(default_blueprint(self.index), make_active=True, make_default=True)
        self.writer.write_static()

    @classmethod
    def open(cls, spec: str, site: Site, tree: LoadedTree, *, app_id: str = "frog-bt"
             ) -> Telemetry:
        """A recording streaming to ``spec`` (see :mod:`frog_bt.telemetry.spec`).

        Raises ValueError for a spec it does not know, before anything starts.
        """
        sink = parse_spec(spec)
        import rerun as rr

        rec = rr.RecordingStream(app_id)
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

    def attach(self, core: Core) -> None:
        """Append the taps to ``core.taps`` (one core per telemetry)."""
        self.rows.attach(core)

    def flush(self) -> None:
        """Write the buffered rows to the recording now."""
        if self._closed:
            return
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
