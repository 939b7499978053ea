"""MCAP recordings of everything the executive receives and sends (CONTRACT §6).

:class:`Recorder` writes one MCAP file with JSON message encoding:

* one channel per ROS topic the executive subscribes to or publishes (channel
  topic = ROS topic, schema name = ROS type, e.g. ``geometry_msgs/PoseStamped``),
  ``/clock`` included under sim time; the message data is the rosbridge ``msg``
  object, exactly as received or sent;
* ``/frontend/in`` and ``/frontend/out``: every UDP datagram from the front-end
  host and to the front end (acks and resends included), data = the datagram's
  bytes;
* ``/frog_bt/tree``: once, the tree that ran as BehaviorTree.CPP v4 XML
  (``{"format", "file", "xml"}``: Groot2 opens the XML);
* the executive's own events, each as itself (:data:`~frog_bt.model.events.Recorded`,
  one tagged union, encoded once: ``{"type": "Ticked", "t", ...}``) on its channel
  (:data:`~frog_bt.model.channels.EVENT_CHANNELS`): ``/frog_bt/tick`` each tick of the
  tree, ``/frog_bt/blame`` after each command the tree node that sent it and the
  blackboard values it read (for replay's divergence report), ``/frog_bt/operator``,
  ``/frog_bt/alert``, ``/frog_bt/links``, ``/frog_bt/doubt`` and ``/frog_bt/fault``
  each operator command with its answer, alert change, change of the links' states,
  robot answer not believed and failure of the executive's own code; replay rebuilds
  the alert book and the staff's decisions from them;
* once, when the executive took something up from before it (a restart),
  ``/frog_bt/restored`` (:mod:`frog_bt.model.channels`);
* metadata ``frog_bt_site``: ``config_sha256``, the site configuration that ran
  (:func:`frog_bt.config.fingerprint`), in every file;
* metadata ``frog_bt_run``: ``id``, the run's UUID (drawn when the executive started
  afresh, kept by one that resumed the run from its checkpoint), ``robot``, the robot's
  configured name (``alerts.robot``), and, in a resumed run's files, ``resumes``: the run
  it carries on (:mod:`frog_bt.model.run`), in every file.
  Live ticks coalesce bursts of inputs and fall wherever the event loop gets to
  them, so replay ticks exactly where the live executive did
  (:mod:`frog_bt.offline.replay`).

Every message is stamped (``log_time`` = ``publish_time``, ns) with the
project-clock time it was received or sent; ``/clock`` with the time it carries
(the time it starts). Under sim time, what arrives before the first ``/clock``
is held and stamped with that first time, so a recording has no zero stamps.

Each channel carries a JSON Schema (encoding ``jsonschema``), so Foxglove
can browse and plot the fields. Writing costs one encoding and one
``add_message`` per message, both in a background job (:mod:`frog_bt.runtime.background`:
at a quiet turn of the event loop, after any input, tick or command that is due), in
order (an event is kept as it is until then); chunks are bounded (:data:`CHUNK_SIZE`,
ended by the recorder in a background job of its own) and flushed at least every
:data:`FLUSH_EVERY` wall seconds, so memory stays small and a crash loses little.
Chunks are zstd-compressed; :func:`frog_bt.live.mcap_speed.install` makes ending one
several times cheaper (its message index packed at once, one compressor reused), byte
for byte as mcap's own.
:meth:`Recorder.close` (idempotent, also run at interpreter exit) writes the summary
and footer: a recording stays valid MCAP when the run command stops on SIGTERM, or on
an exception.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import time
import weakref
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import msgspec
from mcap.writer import CompressionType, Writer

from frog_bt import __version__
from frog_bt.config import fingerprint
from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import decode_datagram
from frog_bt.live import mcap_speed
from frog_bt.model import channels
from frog_bt.model.channels import (
    DATAGRAM_TYPE,
    EVENT_CHANNELS,
    FRONTEND_IN,
    FRONTEND_OUT,
    LINKS,
    OWN_TYPES,
    PRIMER,
    RESTORED,
    SITE_METADATA,
    TREE,
    from_ns,
    schema_for,
    to_ns,
)
from frog_bt.model.events import (
    AlertChanged,
    Blamed,
    Datagram,
    Doubted,
    Event,
    Faulted,
    LinksChanged,
    OperatorDone,
    Recorded,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.run import RUN_METADATA
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS, Keep
from frog_bt.runtime import background
from frog_bt.tree.btcpp import tree_xml
from frog_bt.tree.registry import NodeRegistry

if TYPE_CHECKING:
    from frog_bt.runtime.observer import Host

log = logging.getLogger(__name__)
mcap_speed.install()

# Chunks of 64 KiB compressed with zstd: closing one (compressing it, writing its message
# index) takes ~0.2 ms offline and ~0.6 ms in the running executive (cold caches), where
# 256 KiB with LZ4 took 0.7 and ~1.2 ms, and the file is about a quarter smaller
# (docs/PERFORMANCE.md). mcap would close a chunk inside whichever add_message crossed
# the size, i.e. in the drain right after an input, before the tick that input calls
# for; the recorder ends chunks itself, in a background job, so that the tick goes first.
CHUNK_SIZE = 64 * 1024  # bytes of uncompressed messages per chunk
DRAIN_STEP = 100  # messages written in one background job (~0.3 ms p50 live)
_UNBOUNDED = 1 << 62  # mcap's own chunk size: never reached (the recorder ends chunks)
_RECORD = 31  # bytes of an MCAP message record besides its data (opcode, length, header)
FLUSH_EVERY = 1.0  # wall seconds between chunk flushes: a kill loses at most this much
PRIMER_DATAGRAMS = 16  # recent datagrams in, so that their resends stay duplicates
PRIMER_SEQS = 64  # recent seqs out, so that resends of earlier commands are not new ones
HELD_LIMIT = 10_000  # messages held before the first /clock
RECORDING_MODE = 0o640  # rw owner, r group, nothing for others


def _dumps(msg: Any) -> bytes:
    return json.dumps(msg, separators=(",", ":")).encode()


def _raw(msg: Any) -> bytes:
    """A received ``msg`` as JSON bytes: as it came (raw) when it is raw JSON."""
    return bytes(msg) if isinstance(msg, bytes | msgspec.Raw) else _dumps(msg)


Queued = tuple[int, int, bytes, int]  # channel id, log time (ns), data, sequence
Incoming = tuple[str, float | None, bytes | Recorded]  # topic, time, data or the event


def _write_queued(writer: Writer, queue: list[Queued]) -> None:
    """Write ``queue`` in order, emptying it."""
    for cid, ns, data, seq in queue:
        writer.add_message(cid, log_time=ns, data=data, publish_time=ns, sequence=seq)
    queue.clear()


def _finish(writer: Writer, stream: IO[bytes], queue: list[Queued]) -> None:
    """Write what is queued, summary and footer, close the file (the finalizer: runs once)."""
    try:
        _write_queued(writer, queue)
        writer.finish()
    except Exception:
        log.exception("recording: cannot finish the MCAP file")
    finally:
        stream.close()


class Recorder:
    """Writes an MCAP recording of one executive run; see the module docstring.

    ``Recorder(path)`` creates the file (``OSError`` when it cannot);
    :meth:`attach` hooks it to an :class:`~frog_bt.runtime.executive.Executive`;
    :meth:`rotate` finishes the file and carries on in a new one (``--record DIR``,
    :mod:`frog_bt.live.rotation`); :meth:`close` finishes it. A write error is
    logged once and stops the recording; it never reaches the tick path.
    """

    def __init__(
        self,
        path: Path,
        *,
        chunk_size: int = CHUNK_SIZE,
        flush_every: float = FLUSH_EVERY,
        metadata: dict[str, str] | None = None,
    ) -> None:
        self._chunk_size = chunk_size
        self._ending: object | None = None  # the token of the chunk's end, when one is due
        self._flush_every = flush_every
        # Messages wait in _incoming until a quiet turn of the event loop (after the tick,
        # the input, the command under way), so that a tick pays a list append per
        # message, not an MCAP record each; _queue holds them stamped, for the writer (and
        # the finalizer).
        self._incoming: list[Incoming] = []
        self._queue: list[Queued] = []
        self._drain_scheduled = False
        self._flush_timer: asyncio.TimerHandle | None = None
        self._syncing = False
        self._unsynced = False  # handed to the OS since the last fsync began
        self._synced_at = 0.0  # when the last fsync began (monotonic)
        self._sync_timer: asyncio.TimerHandle | None = None
        self._registered: dict[str, str] = {}  # topic -> type, for the next file too
        self._last_ns = 0
        self._held: list[tuple[str, bytes | Recorded]] = []
        self._ready: Callable[[], bool] = lambda: True
        self._clock_topic: str | None = None
        self._tree: bytes | None = None
        self._site: dict[str, str] = {}  # SITE_METADATA, for the next file too
        self._run: dict[str, str] = {}  # RUN_METADATA, for the next file too
        # What a new file starts with (rotation): the latest message of each input kept
        # as latest, the last /clock, recent datagrams in and the seqs sent out.
        self._latest_topics: frozenset[str] = frozenset()
        self._latest_raw: dict[str, tuple[float, bytes]] = {}
        self._clock_raw: bytes | None = None
        self._frontend_in: deque[bytes] = deque(maxlen=PRIMER_DATAGRAMS)
        self._frontend_out_seqs: deque[int] = deque(maxlen=PRIMER_SEQS)
        self.messages = 0
        self.dropped = 0  # held before the first /clock beyond HELD_LIMIT
        self.closed = False
        self._open(Path(path), metadata)

    def _open(self, path: Path, metadata: dict[str, str] | None) -> None:
        self.path = path
        # owner and group only: a recording holds what the robot saw of its visitors
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, RECORDING_MODE)
        stream: IO[bytes] = os.fdopen(fd, "wb")  # closed by _finish
        os.fchmod(fd, RECORDING_MODE)  # also when the file was there before
        self._stream = stream
        self._writer = Writer(stream, chunk_size=_UNBOUNDED, compression=CompressionType.ZSTD)
        self._chunk_bytes = 0  # in the chunk being written (its uncompressed size)
        self._writer.start(profile="", library=f"frog-bt {__version__}")
        if metadata:
            self._writer.add_metadata("frog_bt", metadata)
        self._queue = []
        self._finalizer = weakref.finalize(self, _finish, self._writer, stream, self._queue)
        self._flushed_at = time.monotonic()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[int, int] = {}
        for topic, type_ in self._registered.items():
            self.channel(topic, type_)

    # ------------------------------------------------------------ wiring

    def attach(self, host: Host) -> None:
        """Register every channel and write the tree (a live host only: a recording needs
        the raw traffic, which a replay has not)."""
        if host.links is None:
            raise ValueError("a recorder attaches to the live executive (raw traffic)")
        site = host.site
        for role, topic in (*INPUTS.items(), *OUTPUTS.items()):
            self.channel(site.topic(role), topic.type)
        self._latest_topics = frozenset(
            site.topic(role) for role, inp in INPUTS.items() if inp.keep is Keep.LATEST
        )
        if host.sim_time:
            self._clock_topic = CLOCK.name
            self.channel(CLOCK.name, CLOCK.type)
        self.channel(FRONTEND_IN, DATAGRAM_TYPE)
        self.channel(FRONTEND_OUT, DATAGRAM_TYPE)
        for channel in EVENT_CHANNELS.values():
            self.channel(channel, OWN_TYPES[channel])
        clock = host.clock
        self._ready = lambda: bool(clock.ready)
        self._site = {"config_sha256": fingerprint(site)}
        self._writer.add_metadata(SITE_METADATA, self._site)
        self._run = host.core.standing.run.metadata(site.alerts.robot)
        self._writer.add_metadata(RUN_METADATA, self._run)
        self._tree = self._tree_message(host)
        if self._tree is not None:
            self._write(TREE, None, self._tree)
        restored = getattr(host, "restored", None)  # the executive's, after a restart
        if isinstance(restored, channels.Restored):
            self.channel(RESTORED, OWN_TYPES[RESTORED])
            self._write(RESTORED, None, channels.encode(restored))

    def on_event(self, event: Event) -> None:
        """Each event its channel (tick path: a list append, see :meth:`_write`): what
        crossed a wire as it crossed, the executive's own events as themselves."""
        match event:
            case RobotInput():
                self._ros_in(event)
            case RobotCommand():
                self._ros_out(event)
            case Datagram():
                self._datagram(event)
            case LinksChanged():  # before the clock has a time: held
                self._write(LINKS, event.t if self._ready() else None, event)
            case Ticked() | Blamed() | OperatorDone() | AlertChanged() | Doubted() | Faulted():
                self._write(EVENT_CHANNELS[type(event)], event.t, event)
            case _:
                pass  # told by the events around it (FrontendIn, FrontendOut: datagrams)

    def channel(self, topic: str, type_: str) -> str:
        """Register ``topic`` (and its schema) in the file on first use; the topic."""
        if topic not in self._channels:
            sid = self._schemas.get(type_)
            if sid is None:
                schema = schema_for(type_)
                sid = self._writer.register_schema(type_, "jsonschema", _dumps(schema))
                self._schemas[type_] = sid
            self._channels[topic] = self._writer.register_channel(topic, "json", sid)
            self._registered.setdefault(topic, type_)
        return topic

    # ------------------------------------------------------------ events (tick path: keep cheap)

    def _ros_in(self, event: RobotInput) -> None:
        t, topic = event.t, event.topic
        if event.raw is None:
            return  # nothing as received (a host without raw traffic)
        if topic not in self._channels:
            self.channel(topic, "unknown")
        data = _raw(event.raw)
        if topic == self._clock_topic:
            try:  # /clock is seen before the clock takes it: stamp it with its own time
                clock = CLOCK.codec.decode(data)
            except DecodeError:
                pass
            else:
                self._clock_raw = data
                self._write(topic, max(t, clock) if self._ready() else clock, data)
                return
        if topic in self._latest_topics:
            self._latest_raw[topic] = (t, data)
        self._write(topic, t if self._ready() else None, data)

    def _ros_out(self, event: RobotCommand) -> None:
        topic = event.topic
        if topic not in self._channels:
            self.channel(topic, "unknown")
        self._write(topic, event.t, _dumps(event.msg))

    def _datagram(self, event: Datagram) -> None:
        data, t = event.data, event.t
        if event.direction == "in":
            topic = FRONTEND_IN
            self._frontend_in.append(data)
        else:
            topic = FRONTEND_OUT
            try:
                seq: int | None = decode_datagram(data).seq
            except DecodeError:
                seq = None
            if seq is not None and seq not in self._frontend_out_seqs:
                self._frontend_out_seqs.append(seq)
        self._write(topic, t if self._ready() else None, data)

    def _tree_message(self, host: Host) -> bytes | None:
        """The tree that runs, so that a recording explains itself without the files."""
        tree = getattr(host.core, "tree", None)
        if tree is None or not isinstance(tree.factory, NodeRegistry):
            return None
        try:
            tree_file = Path(tree.file)
            xml = tree_xml(tree_file, host.site, tree.factory)
        except Exception as exc:
            log.info("recording without the tree's XML: %s", exc)
            return None
        return channels.encode(channels.Tree("BehaviorTree.CPP v4", str(tree_file), xml))

    # ------------------------------------------------------------ writing

    def _write(self, topic: str, t: float | None, data: bytes | Recorded) -> None:
        """Take a message (``t`` None: before the clock has a time), its bytes or the event
        it is; it is stamped, encoded and written once the event loop's current callback
        is over (at once without a loop)."""
        if self.closed:
            return
        self._incoming.append((topic, t, data))
        self._drain_soon()

    def _stamp(self) -> None:
        """Give the incoming messages their log times and sequence numbers, in order."""
        incoming, self._incoming = self._incoming, []
        for topic, t, data in incoming:
            if t is None:  # before the first /clock: no time yet
                if len(self._held) < HELD_LIMIT:
                    self._held.append((topic, data))
                else:
                    self.dropped += 1
                continue
            ns = max(to_ns(t), self._last_ns)
            if self._held:
                held, self._held = self._held, []
                for held_topic, held_data in held:
                    self._add(held_topic, ns, held_data)
            self._add(topic, ns, data)
            self._last_ns = ns

    def _add(self, topic: str, ns: int, data: bytes | Recorded) -> None:
        if not isinstance(data, bytes):  # an event: encoded once, as itself
            data = channels.encode(data)
        cid = self._channels.get(topic)
        if cid is None:  # a channel of ours, first used now (or an unknown topic)
            cid = self._channels[self.channel(topic, OWN_TYPES.get(topic, "unknown"))]
        seq = self._sequence.get(cid, 0)
        self._sequence[cid] = seq + 1
        self._queue.append((cid, ns, data, seq & 0xFFFFFFFF))
        self.messages += 1

    def _drain(self) -> None:
        """Write the queued messages, in order, at most :data:`DRAIN_STEP` in a job (the
        rest in the next) and never past a full chunk: a chunk that is full or
        ``flush_every`` s old is ended first (:meth:`_end_chunk`, which drains on)."""
        self._drain_scheduled = False
        if self.closed:
            return  # close() wrote them
        try:
            self._stamp()
            if self._ending is not None:
                return  # the chunk is due to end: its end drains on after it
            queue, writer, size = self._queue, self._writer, self._chunk_size
            n = 0
            for cid, ns, data, seq in queue:
                if n == DRAIN_STEP or self._chunk_bytes >= size:
                    break
                writer.add_message(cid, log_time=ns, data=data, publish_time=ns, sequence=seq)
                self._chunk_bytes += len(data) + _RECORD
                n += 1
            del queue[:n]  # in place: the finalizer holds this list
            due = time.monotonic() - self._flushed_at >= self._flush_every
            if self._chunk_bytes >= size or due:
                self._end_chunk_soon()
            elif queue:
                self._drain_soon()
            elif self._flush_timer is None:  # a quiet spell must not keep the tail back
                try:
                    loop = asyncio.get_running_loop()
                except RuntimeError:
                    return
                self._flush_timer = loop.call_later(self._flush_every, self._timed_flush)
        except Exception as exc:  # disk full, ...: stop recording, never stop the robot
            self._failed(exc)

    def _drain_soon(self) -> None:
        if not self._drain_scheduled:
            self._drain_scheduled = True
            background.soon(self._drain)  # at once without an event loop

    def _end_chunk_soon(self) -> None:
        """End the chunk in a background job: what is due meanwhile (the tick an input
        calls for, its command) goes first. At once without an event loop."""
        if self._ending is None:
            token = self._ending = object()
            background.soon(lambda: self._end_chunk(token))

    def _end_chunk(self, token: object) -> None:
        if self._ending is token:  # not for a file closed meanwhile
            self._ending = None
            self._flush_safely()
            if self._queue or self._incoming:
                self._drain_soon()

    def _timed_flush(self) -> None:
        self._flush_timer = None
        self._end_chunk_soon()

    def _flush_safely(self) -> None:
        """:meth:`_flush` from a timer: an error stops the recording, never the robot."""
        if not self.closed:
            try:
                self._flush()
            except Exception as exc:
                self._failed(exc)

    def _flush(self) -> None:
        """End the chunk and hand it to the OS (a kill -9 then loses nothing of it), and
        ask for it on the disk (power loss): :meth:`_sync_soon`."""
        self._flushed_at = time.monotonic()
        self._chunk_bytes = 0
        self._writer.flush()
        self._stream.flush()
        self._unsynced = True
        self._sync_soon()

    def _sync_soon(self) -> None:
        """``fsync`` what was handed to the OS, in a worker thread, off the event loop, at
        most once every ``flush_every`` seconds (chunks end more often at high rates;
        each sync wakes a thread): a power loss loses at most that long."""
        if self._syncing or self._sync_timer is not None:
            return  # the sync under way, or the one due, covers it (_synced)
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            return
        wait = self._synced_at + self._flush_every - time.monotonic()
        if wait > 0:
            self._sync_timer = loop.call_later(wait, self._sync_now)
        else:
            self._sync_now()

    def _sync_now(self) -> None:
        self._sync_timer = None
        if self.closed or not self._unsynced:
            return
        self._unsynced, self._syncing = False, True
        self._synced_at = time.monotonic()
        future = asyncio.get_running_loop().run_in_executor(None, _fsync, self._stream)
        future.add_done_callback(self._synced)

    def _synced(self, _future: object) -> None:
        self._syncing = False
        if self._unsynced:  # handed to the OS while that sync ran
            self._sync_soon()

    def _failed(self, exc: Exception) -> None:
        log.error("recording to %s stopped: %s", self.path, exc)
        self._queue.clear()
        self.close()

    def primer(self, frontend_ready: bool, staff: channels.Carried | None = None) -> bytes:
        """A :data:`PRIMER` message: what the executive carries from before now
        (``staff``: beside the tree, the staff's decisions and the alert book)."""
        return channels.encode(
            channels.Primer(
                inputs=[
                    channels.PrimerInput(topic, t, msgspec.Raw(data))
                    for topic, (t, data) in sorted(self._latest_raw.items())
                ],
                frontend_ready=frontend_ready,
                frontend_in=[d.decode("utf-8", "replace") for d in self._frontend_in],
                frontend_out_seqs=list(self._frontend_out_seqs),
                staff=staff,
            )
        )

    def rotate(
        self, path: Path, metadata: dict[str, str] | None = None, primer: bytes | None = None
    ) -> None:
        """Finish this file and go on in ``path``: it starts with the tree, the last
        /clock and ``primer`` (on :data:`PRIMER`), stamped now."""
        if self.closed:
            return
        self._stamp()
        self._close_file()
        try:
            self._open(Path(path), metadata)
        except OSError as exc:
            log.error("recording to %s stopped: %s", path, exc)
            self.closed = True
            return
        if self._site:
            self._writer.add_metadata(SITE_METADATA, self._site)
        if self._run:
            self._writer.add_metadata(RUN_METADATA, self._run)
        if self._tree is not None:
            self._write(TREE, None, self._tree)
        if self._clock_raw is not None and self._clock_topic is not None:
            self._write(self._clock_topic, from_ns(self._last_ns), self._clock_raw)
        if primer is not None:
            self._write(PRIMER, from_ns(self._last_ns), primer)

    def _close_file(self) -> None:
        if self._flush_timer is not None:
            self._flush_timer.cancel()
            self._flush_timer = None
        if self._sync_timer is not None:
            self._sync_timer.cancel()
            self._sync_timer = None
        self._unsynced = False
        self._ending = None
        self._finalizer()

    def close(self) -> None:
        """Write the summary and footer and close the file; idempotent."""
        if self.closed:
            return
        try:
            self._stamp()
        except Exception as exc:  # a bug: what is stamped is still written
            log.error("recording to %s: %s", self.path, exc)
        self.closed = True
        if self._held:
            log.warning(
                "recording: %d messages before the first /clock were never stamped", len(self._held)
            )
            self._held = []
        if self.dropped:
            log.warning("recording: %d messages before the first /clock dropped", self.dropped)
        self._close_file()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _fsync(stream: IO[bytes]) -> None:
    with contextlib.suppress(OSError, ValueError):  # closed meanwhile: close synced it
        os.fsync(stream.fileno())
