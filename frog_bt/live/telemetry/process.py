"""Live telemetry written by a process of its own.

On the robot, ``frog-bt run --rerun SPEC`` keeps only the taps
(:class:`~frog_bt.live.telemetry.rows.Rows`: appends on the tick path) in the
executive. Every ``batch_ticks`` ticks the rows go, as one batch, into a bounded
queue to a child process that owns the rerun recording stream
(:class:`~frog_bt.live.telemetry.Telemetry` there) and does all the formatting and
logging. So:

* the tick never waits for rerun: the batch is pickled once the tick is over, in
  steps of :data:`STEP_ROWS` rows, each a background job
  (:mod:`frog_bt.runtime.background`: at a quiet turn of the event loop), so that an
  input arriving meanwhile (and the tick it calls for, and its command) goes first: it
  waits for one step at most (~0.1 ms), never for a whole batch (1-3 ms with many
  inputs); the queue's feeder
  thread only copies bytes; the child merges batches for a file
  (:class:`_Pending`: fewer, larger rerun chunks, a smaller file);
* the rerun SDK's own memory, which grows with every row it has logged (see
  docs/PERFORMANCE.md), is the child's, not the executive's; and the child is
  replaced by a fresh one every :data:`RECYCLE_ROWS` rows, which gives that
  memory back. A ``save:`` recording then goes on in ``FILE.2.rrd``,
  ``FILE.3.rrd``, ... (the viewer opens them together: one recording id);
  ``spawn``, ``connect`` and ``serve`` keep streaming to the same viewer;
* a full queue (a child that cannot keep up, or died) drops the batch, counted
  and logged at most once a minute: telemetry never stops the robot.

The child is forked (it inherits the site and the tree, and never the parent's
event loop); on platforms without ``fork`` the live executive writes in-process.
"""

from __future__ import annotations

import contextlib
import io
import logging
import multiprocessing
import multiprocessing.queues
import pickle
import queue
import time
import uuid
from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from frog_bt.errors import DecodeError
from frog_bt.live.telemetry.layout import TreeIndex
from frog_bt.live.telemetry.observer import TelemetryObserver
from frog_bt.live.telemetry.priority import ChildPriority, can_raise, enter, leave
from frog_bt.live.telemetry.rows import Batch
from frog_bt.live.telemetry.spec import parse_spec
from frog_bt.model.links import LinkStatus
from frog_bt.model.wire import INPUTS
from frog_bt.runtime import background
from frog_bt.warning_limit import WarningLimiter

if TYPE_CHECKING:
    from frog_bt.config import Site
    from frog_bt.live.telemetry import Telemetry
    from frog_bt.tree.loader import LoadedTree

log = logging.getLogger(__name__)
QUEUE_BATCHES = 64  # batches waiting for the child (50 ticks each: 5 minutes at 10 Hz)
RECYCLE_ROWS = 250_000  # rows a child writes before a fresh one takes over (~20 min)
CLOSE_TIMEOUT = 6.0  # seconds close() waits for the child to finish its file
TIMINGS = 1000  # hand-overs whose cost is kept (Timings), for scripts/bench
MERGE_BATCHES = 10  # batches a save: file is written in at once (500 ticks, 50 s at 10 Hz)
HOLD = 60.0  # seconds the child holds a batch for a save: file at most
STEP_ROWS = 64  # rows pickled per step of a batch (~0.1 ms; an input waits for one step)


def available() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


Item = tuple[object, ...]  # ("batch", bytes) | ("links", tick, t, changes) | ("close",)


class Timings:
    """What the last :data:`TIMINGS` hand-overs cost the executive, in ns of its thread's
    CPU time: ``serialise`` (a batch to bytes, its steps summed), ``serialise_step`` (one
    step: the longest an input may wait for it) and ``hand_over`` (into the queue)."""

    def __init__(self) -> None:
        self.serialise: deque[int] = deque(maxlen=TIMINGS)
        self.serialise_step: deque[int] = deque(maxlen=TIMINGS * 8)
        self.hand_over: deque[int] = deque(maxlen=TIMINGS)


def _pieces(batch: Batch, rows: int) -> Iterator[tuple[int, list[Any]]]:
    """The batch as (column, up to ``rows`` rows) pieces, in column order."""
    for column, values in enumerate(batch.columns()):
        for start in range(0, len(values), rows):
            yield column, values[start : start + rows]


class Serialising:
    """One batch being pickled, :data:`STEP_ROWS` rows per :meth:`step`, with one pickler
    (a class is named once per batch, not per step; its memo holds the rows until the
    bytes are taken, as the batch itself would). The inputs are pickled as received
    (``Rows.raw_inputs``: the rosbridge bytes), ten times faster than their Structs."""

    def __init__(self, batch: Batch, rows: int = STEP_ROWS) -> None:
        self.rows = len(batch)
        self.ticks = bool(batch.statuses)  # the tree's rows among them
        self._stream = io.BytesIO()
        self._pickler = pickle.Pickler(self._stream, protocol=pickle.HIGHEST_PROTOCOL)
        self._pieces = _pieces(batch, rows)
        self.ns = 0  # thread CPU time spent so far

    def step(self) -> bool:
        """Pickle the next piece; False once the batch is done."""
        t0 = time.thread_time_ns()
        piece = next(self._pieces, None)
        if piece is not None:
            self._pickler.dump(piece)
        self.ns += time.thread_time_ns() - t0
        return piece is not None

    def bytes(self) -> bytes:
        while self.step():
            pass
        return self._stream.getvalue()


def serialise(batch: Batch) -> bytes:
    """A batch as bytes for the child, at once (see :class:`Serialising`)."""
    return Serialising(batch).bytes()


def deserialise(data: bytes) -> Batch:
    """The child's side of :class:`Serialising`: the pieces, in order, as one batch;
    inputs decoded again by their topic's codec."""
    stream = io.BytesIO(data)
    unpickler = pickle.Unpickler(stream)  # one, as one pickler wrote them (its memo)
    batch = Batch()
    columns = batch.columns()
    while stream.tell() < len(data):
        column, rows = unpickler.load()
        columns[column].extend(rows)
    inputs = batch.inputs
    for n, (tick, t, role, value) in enumerate(inputs):
        if isinstance(value, msgspec.Raw):
            try:
                inputs[n] = (tick, t, role, INPUTS[role].codec.decode(bytes(value)))
            except DecodeError:
                inputs[n] = (tick, t, role, None)
    batch.inputs = [row for row in inputs if row[3] is not None]
    return batch


class _Pending:
    """Batches the child holds to write as one: rerun writes a chunk per entity and call,
    so fewer, larger calls cost the child less CPU and make a smaller file (measured in
    docs/PERFORMANCE.md: half the CPU and a third less .rrd for 4 batches as one).

    A ``save:`` file is written every :data:`MERGE_BATCHES` batches (500 ticks: 50 s at
    10 Hz) or :data:`HOLD` seconds after the first one held; a live viewer (``spawn``,
    ``connect``, ``serve``) gets each batch at once, merged only with those already
    queued behind it (a writer that fell behind catches up in fewer calls)."""

    def __init__(self, telemetry: Telemetry, live: bool) -> None:
        self.telemetry = telemetry
        self.live = live
        self.batch: Batch | None = None
        self.held = 0  # batches in self.batch
        self.since = 0.0  # monotonic time of the first one held

    def add(self, data: bytes) -> None:
        try:
            batch = deserialise(data)
        except Exception:
            log.exception("rerun telemetry: could not read a batch")
            return
        if self.batch is None:
            self.batch, self.since = batch, time.monotonic()
        else:
            self.batch.extend(batch)
        self.held += 1
        if self.held >= MERGE_BATCHES:
            self.write()

    def wait(self, idle: float) -> float:
        """How long the child may wait for the next item before writing what it holds."""
        if self.batch is None:
            return idle
        if self.live:
            return 0.0
        return max(0.0, self.since + HOLD - time.monotonic())

    def write(self) -> None:
        batch, self.batch, self.held = self.batch, None, 0
        if batch is None:
            return
        try:
            self.telemetry.writer.write(batch)
        except Exception:
            log.exception("rerun telemetry: could not write a batch")


def _serve(
    spec: str,
    site: Site,
    tree: LoadedTree,
    recording_id: str,
    inbox: multiprocessing.queues.Queue[Item],
    idle: bool = False,
) -> None:
    """The child: write what comes until ``close`` (or the parent is gone); in the idle
    scheduling class when ``idle`` (:mod:`~frog_bt.live.telemetry.priority`)."""
    from frog_bt.live.telemetry import Telemetry

    enter(idle)
    telemetry = Telemetry.open(spec, site, tree, recording_id=recording_id)
    pending = _Pending(telemetry, live=parse_spec(spec).kind != "save")
    try:
        while True:
            wait = pending.wait(5.0)
            try:
                item = inbox.get(timeout=wait) if wait > 0 else inbox.get_nowait()
            except queue.Empty:
                if pending.batch is not None:
                    pending.write()
                    continue
                parent = multiprocessing.parent_process()
                if parent is None or not parent.is_alive():
                    return  # the executive was killed: finish the file
                continue
            kind = item[0]
            if kind == "batch":
                data = item[1]
                assert isinstance(data, bytes)
                pending.add(data)
                continue
            pending.write()  # what came before goes first
            if kind == "tree":
                telemetry.writer.reload(*item[1:])  # type: ignore[arg-type]
            elif kind == "links":
                telemetry.writer.write_links(*item[1:])  # type: ignore[arg-type]
            elif kind == "close":
                if idle:
                    leave()
                return
    finally:
        pending.write()
        telemetry.close()


def _numbered(spec: str, n: int) -> str:
    """``save:tour.rrd`` for the first child, ``save:tour.2.rrd`` for the second, ..."""
    sink = parse_spec(spec)
    if sink.kind != "save" or n == 1:
        return spec
    path = Path(sink.target)
    return f"save:{path.with_suffix(f'.{n}{path.suffix}')}"


class TelemetryProcess(TelemetryObserver):
    """The executive's side: rows buffered here, written by a child; see the module
    docstring. Attached and closed like :class:`~frog_bt.live.telemetry.Telemetry`."""

    def __init__(
        self,
        spec: str,
        site: Site,
        tree: LoadedTree,
        *,
        batch_ticks: int = 50,
        recycle_rows: int | None = None,
    ) -> None:
        parse_spec(spec)  # ValueError for a spec it does not know, before anything starts
        super().__init__(site, tree, batch_ticks=batch_ticks)
        self.rows.raw_inputs = True
        self.timings = Timings()
        self.spec = spec
        self.recording_id = str(uuid.uuid4())
        self.recycle_rows = recycle_rows or RECYCLE_ROWS
        self._context = multiprocessing.get_context("fork")
        self.children = 0
        self.dropped = 0  # batches not written (the queue was full)
        self._written = 0  # rows sent to the current child
        self._serialising: deque[Serialising] = deque()  # batches being pickled, oldest first
        self._stepping = False  # a step is due (a background job)
        self._warnings = WarningLimiter(60.0, logger=log)
        self._idle = can_raise()  # the child in the idle class, raised when behind
        self._start_child()

    def _start_child(self) -> None:
        self.children += 1
        self._inbox = self._context.Queue(maxsize=QUEUE_BATCHES)
        self._child = self._context.Process(
            target=_serve,
            name=f"frog-bt telemetry {self.children}",
            daemon=True,
            args=(
                _numbered(self.spec, self.children),
                self.site,
                self.tree,
                self.recording_id,
                self._inbox,
                self._idle,
            ),
        )
        self._child.start()
        assert self._child.pid is not None
        self.priority = ChildPriority(self._child.pid, idle=self._idle)
        self._written = 0

    def _stop_child(self, timeout: float) -> None:
        inbox, child = self._inbox, self._child
        self.priority.finish()
        with contextlib.suppress(queue.Full):
            inbox.put(("close",), timeout=timeout)
        inbox.close()
        inbox.join_thread()
        child.join(timeout)
        if child.is_alive():
            log.warning("rerun telemetry: the writer did not finish within %.0f s", timeout)
            child.terminate()
            child.join(1.0)

    # ------------------------------------------------------------ the executive's side

    def _write_links(self, tick: int, t: float, changes: list[tuple[str, LinkStatus]]) -> None:
        self._send(("links", tick, t, changes))

    def _write_tree(self, tick: int, t: float, index: TreeIndex, generation: int) -> None:
        self._send(("tree", tick, t, index, generation))

    def _flush_soon(self) -> None:
        """After the tick that filled the rows: pickle them in steps (:meth:`_step`)."""
        self._flush_pending = False
        if self._closed:
            return
        batch = self.rows.drain()
        if len(batch):
            self._serialising.append(Serialising(batch))
            if not self._stepping:
                self._stepping = True
                background.soon(self._step)

    def _step(self) -> None:
        """One step of the oldest batch being pickled (handed over when done); the next
        is another background job: an input that is ready, the tick it calls for and its
        command go first."""
        self._stepping = False
        if not self._serialising or self._closed:
            return
        work = self._serialising[0]
        t0 = time.thread_time_ns()
        more = work.step()
        self.timings.serialise_step.append(time.thread_time_ns() - t0)
        if not more:
            self._serialising.popleft()
            self._hand_over(work)
        if self._serialising:
            self._stepping = True
            background.soon(self._step)

    def flush(self, until: float | None = None) -> None:
        """Send the buffered rows to the child now, after any batch still being pickled;
        a full queue drops them, or (closing) is waited for until ``until`` (monotonic)."""
        self._flush_pending = False
        if self._closed:
            return
        while self._serialising:  # a step still due finds none left
            self._hand_over(self._serialising.popleft(), until)
        batch = self.rows.drain()
        if len(batch):
            self._hand_over(Serialising(batch), until)

    def _hand_over(self, work: Serialising, until: float | None = None) -> None:
        if self._written >= self.recycle_rows and work.ticks:
            # only now, with ticks to write: a new file never holds just the last link
            # change or log line of a day that ended at the old one's limit
            self._recycle()
        data = work.bytes()  # what is left of it, at once
        t1 = time.thread_time_ns()
        sent = self._send(("batch", data), until)
        self.timings.serialise.append(work.ns)
        self.timings.hand_over.append(time.thread_time_ns() - t1)
        if sent:
            self._written += work.rows

    def _recycle(self) -> None:
        """A fresh child for the next file, its link lanes starting where they are."""
        self._stop_child(CLOSE_TIMEOUT)
        self._start_child()
        links, self._links = self._links, {}  # the new file's lanes start with them
        core = self._host.core if self._host is not None else None
        if links and core is not None:
            self._send(("links", core.ticks, core.clock.now(), list(links.items())))
            self._links = links

    def _send(self, item: Item, until: float | None = None) -> bool:
        if self._closed:
            return False
        try:
            if until is None:
                self._inbox.put_nowait(item)
            else:  # closing: the child is taking the rest
                self._inbox.put(item, timeout=max(0.0, until - time.monotonic()))
            self.priority.follow(self._inbox.qsize)
            return True
        except queue.Full:
            self.priority.follow(lambda: QUEUE_BATCHES)
            self.dropped += 1
            self._warnings.warn(
                "full",
                f"rerun telemetry: the writer is behind; {self.dropped} batches dropped so far",
            )
            return False

    def close(self) -> None:
        """Send what is left, let the child finish its file (bounded). Idempotent."""
        if self._closed:
            return
        self.priority.finish()  # at niceness 5: it takes the rest and finishes its file
        self.flush(until=time.monotonic() + CLOSE_TIMEOUT)  # what is left is not dropped
        self._closed = True
        self.rows.detach()
        self._stop_child(CLOSE_TIMEOUT)
