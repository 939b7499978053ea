"""Live telemetry in a process of its own: the executive keeps the taps, a child writes."""

from __future__ import annotations

import asyncio
import queue
import subprocess
import sys
from collections import deque
from pathlib import Path

import pytest

from frog_bt.live.telemetry import process
from frog_bt.live.telemetry.process import _numbered, _Pending, serialise
from frog_bt.live.telemetry.rows import Batch

ROOT = Path(__file__).resolve().parents[2]


def test_recycled_writers_go_on_in_numbered_files() -> None:
    assert _numbered("save:/x/tour.rrd", 1) == "save:/x/tour.rrd"
    assert _numbered("save:/x/tour.rrd", 3) == "save:/x/tour.3.rrd"
    assert _numbered("spawn", 2) == "spawn"  # the same viewer, the same recording id


class _Writer:
    def __init__(self) -> None:
        self.written: list[Batch] = []

    def write(self, batch: Batch) -> None:
        self.written.append(batch)


class _Telemetry:
    def __init__(self) -> None:
        self.writer = _Writer()


def _batch(tick: int) -> bytes:
    return serialise(Batch(poses=[(tick, 100.0 + tick, 1.0, 2.0, 0.0)], notes=[]))


def test_a_file_writer_merges_batches_a_live_one_writes_at_once() -> None:
    """The child holds batches for a save: file and writes them as one (fewer, larger rerun
    chunks), in order; for a live viewer it writes as soon as nothing more is queued."""
    telemetry = _Telemetry()
    pending = _Pending(telemetry, live=False)  # type: ignore[arg-type]
    for tick in range(1, process.MERGE_BATCHES):
        pending.add(_batch(tick))
    assert telemetry.writer.written == [] and 0 < pending.wait(5.0) <= process.HOLD
    pending.add(_batch(process.MERGE_BATCHES))  # the tenth: written at once, as one
    [merged] = telemetry.writer.written
    assert [row[0] for row in merged.poses] == list(range(1, process.MERGE_BATCHES + 1))
    assert pending.batch is None and pending.wait(5.0) == 5.0

    live = _Pending(telemetry, live=True)  # type: ignore[arg-type]
    live.add(_batch(1))
    live.add(_batch(2))  # already queued behind the first: merged
    assert live.wait(5.0) == 0.0  # nothing more queued: written now
    live.write()
    assert [row[0] for row in telemetry.writer.written[-1].poses] == [1, 2]


def test_a_tour_is_written_by_writers_that_take_turns(tmp_path: Path) -> None:
    """`frog-bt demo --rerun save:F.rrd` with a writer recycled every 3,000 rows (in a
    fresh interpreter: the child is forked before rerun is imported anywhere): several
    files, one recording id, each with the static scene and rows of its own, and the
    link lanes carried into each new file."""
    code = (
        "import sys, frog_bt.live.telemetry.process as p; p.RECYCLE_ROWS = 3000\n"
        "from frog_bt.cli import main\n"
        "sys.exit(main(['demo', '--quiet', '--speed', '300', '--rerun', "
        "'save:' + sys.argv[1], '--record', sys.argv[2]]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path / "t.rrd"), str(tmp_path / "t.mcap")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    files = sorted(tmp_path.glob("t*.rrd"))
    assert len(files) >= 3 and tmp_path / "t.rrd" in files and tmp_path / "t.2.rrd" in files

    from rerun.chunk import RrdReader

    ids = set()
    for path in files:
        static, temporal = set(), set()
        for chunk in RrdReader(path).stream():
            (static if chunk.is_static else temporal).add(chunk.entity_path.split("/")[1])
        assert {"map", "bt", "links"} <= static, (path.name, static)
        assert "links" in temporal and "bt" in temporal, (path.name, temporal)
        ids |= {entry.recording_id for entry in RrdReader(path).recordings()}
    assert len(ids) == 1  # the viewer opens them together as one recording


def test_a_batch_pickled_in_steps_reads_back_whole() -> None:
    rows = 5 * process.STEP_ROWS + 3
    batch = Batch(
        poses=[(n, 100.0 + n, 1.0, 2.0, 0.0) for n in range(rows)],
        statuses=[(n, 100.0 + n, ((1, 0), (n % 7, 2))) for n in range(rows)],
        marks=[(3, 103.0, "staff", "INFO", "pause (web): done")],
    )
    work = process.Serialising(batch)
    steps = 0
    while work.step():
        steps += 1
    assert steps == 2 * 6 + 1  # no step pickles more than STEP_ROWS rows
    back = process.deserialise(work.bytes())
    assert back.columns() == batch.columns()


def test_inputs_go_before_a_batch_being_pickled(monkeypatch: pytest.MonkeyPatch) -> None:
    """A full batch is pickled in steps after the tick: a callback that is ready meanwhile
    (an input, the tick it calls for) runs before the batch is done and handed over."""
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site

    sent: list[process.Item] = []
    monkeypatch.setattr(process.TelemetryProcess, "_start_child", lambda self: None)
    site = load_site()
    telemetry = process.TelemetryProcess("save:unused.rrd", site, load_tree(site=site))
    poses = [(n, 100.0 + n, 1.0, 2.0, 0.0) for n in range(10 * process.STEP_ROWS)]

    async def scenario() -> list[tuple[str, int]]:
        order: list[tuple[str, int]] = []
        handed = asyncio.Event()
        monkeypatch.setattr(
            process.TelemetryProcess,
            "_send",
            lambda self, item, until=None: (sent.append(item), handed.set(), True)[-1],
        )
        telemetry.rows.batch.poses.extend(poses)
        telemetry._flush_soon()  # as after the tick that filled the rows
        asyncio.get_running_loop().call_soon(lambda: order.append(("input", len(sent))))
        await handed.wait()
        order.append(("handed over", len(sent)))
        return order

    assert asyncio.run(scenario()) == [("input", 0), ("handed over", 1)]
    [(kind, data)] = sent
    assert kind == "batch" and isinstance(data, bytes)
    assert process.deserialise(data).poses == poses
    telemetry._closed = True  # no child to stop


def test_a_fresh_writer_starts_only_when_there_are_ticks_to_write() -> None:
    """Past its rows, a child is replaced only before the next batch with ticks: the day's
    last log line (or link change) goes into the file that has the ticks before it, never
    into a new file of its own (seen: a demo's last file held a log line and no tree)."""
    telemetry = object.__new__(process.TelemetryProcess)
    telemetry._closed, telemetry._links, telemetry._host = False, {}, None
    telemetry.timings, telemetry.recycle_rows, telemetry._written = process.Timings(), 2, 0
    telemetry._stepping, telemetry._serialising = None, deque()
    started: list[int] = []
    sent: list[str] = []

    def start() -> None:
        started.append(len(sent))
        telemetry._written = 0

    telemetry._start_child = start
    telemetry._stop_child = lambda timeout: None
    telemetry._send = lambda item, until=None: sent.append(str(item[0])) is None
    ticks = Batch(statuses=[(t, t / 10, ((0, 1),)) for t in (1, 2, 3)])
    last_line = Batch(notes=[(4, 0.4, "tour over", "info")])
    queued = [ticks, last_line]
    telemetry.rows = type("Rows", (), {"drain": lambda self: queued.pop(0)})()
    telemetry.flush()
    telemetry.flush()
    assert sent == ["batch", "batch"] and started == []  # past 2 rows, but no tick since
    queued.append(Batch(statuses=[(5, 0.5, ((0, 2),))]))
    telemetry.flush()
    assert started == [2] and sent == ["batch", "batch", "batch"]  # the new file: ticks


def test_closing_waits_for_room_in_the_queue_rather_than_dropping(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """At close the rest goes to the child even when its queue is full for now (it is
    taking them): waited for, bounded by CLOSE_TIMEOUT, not dropped."""
    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.live.telemetry.priority import ChildPriority

    class Inbox:  # full to put_nowait; room after a wait
        def __init__(self) -> None:
            self.items: list[process.Item] = []

        def put_nowait(self, item: process.Item) -> None:
            raise queue.Full

        def put(self, item: process.Item, timeout: float) -> None:
            assert 0 < timeout <= process.CLOSE_TIMEOUT
            self.items.append(item)

        def qsize(self) -> int:
            return len(self.items)

    monkeypatch.setattr(process.TelemetryProcess, "_start_child", lambda self: None)
    monkeypatch.setattr(process.TelemetryProcess, "_stop_child", lambda self, timeout: None)
    site = load_site()
    telemetry = process.TelemetryProcess("save:unused.rrd", site, load_tree(site=site))
    telemetry.priority = ChildPriority(0, idle=False)
    inbox = Inbox()
    telemetry._inbox = inbox  # type: ignore[assignment]
    for n in range(3):  # batches still being pickled, and rows not yet drained
        telemetry._serialising.append(
            process.Serialising(Batch(poses=[(n, 100.0 + n, 1.0, 2.0, 0.0)], notes=[]))
        )
    telemetry.rows.batch.poses.append((3, 103.0, 1.0, 2.0, 0.0))
    telemetry._send(("links", 1, 100.0, []))  # while running: dropped, counted
    assert telemetry.dropped == 1
    telemetry.close()
    assert telemetry.dropped == 1 and [kind for kind, *_ in inbox.items] == ["batch"] * 4
    poses = [process.deserialise(data).poses[0][0] for _, data in inbox.items]  # type: ignore[arg-type]
    assert poses == [0, 1, 2, 3]
