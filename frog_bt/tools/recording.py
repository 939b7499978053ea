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
* ``/frog_bt/blame``: after each command, the tree node that sent it
  (``{"channel", "node"}``), for replay's divergence report;
* ``/frog_bt/tick``: one message per tick of the tree (``{"tick", "status"}``).
  Live ticks coalesce bursts of inputs and fall wherever the event loop gets to
  them, so replay ticks exactly where the live executive did
  (:mod:`frog_bt.tools.replay`).

Every message is stamped (``log_time`` = ``publish_time``, ns) with the
project-clock time it was received or sent; ``/clock`` with the time it carries
(the time it starts). Under sim time, what arrives before the first ``/clock``
is held and stamped with that first time, so a recording has no zero stamps.

Each channel carries a JSON Schema (encoding ``jsonschema``), so Foxglove
can browse and plot the fields. Writing costs one ``json.dumps`` and one
``add_message`` per message, the latter once the event loop's current callback
(a tick, an input) is over, in order; chunks are bounded (:data:`CHUNK_SIZE`) and
flushed at least every :data:`FLUSH_EVERY` wall seconds, so memory stays small
and a crash loses little. :meth:`Recorder.close` (idempotent, also run at
interpreter exit) writes the summary and footer: a recording stays valid MCAP
when the run command stops on SIGTERM, or on an exception.
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import time
import weakref
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import msgspec
from mcap.writer import CompressionType, Writer

from frog_bt import __version__
from frog_bt.errors import DecodeError
from frog_bt.frontend.messages import COMMANDS, EVENTS
from frog_bt.rosbridge.msgs import ROS_TYPES
from frog_bt.wire import CLOCK, INPUTS, OUTPUTS

log = logging.getLogger(__name__)

FRONTEND_IN = "/frontend/in"
FRONTEND_OUT = "/frontend/out"
TICK = "/frog_bt/tick"
BLAME = "/frog_bt/blame"  # the tree node that sent each command, right after it
BLAME_TYPE = "frog_bt/Blame"
TREE = "/frog_bt/tree"  # the tree that ran, as BehaviorTree.CPP v4 XML, once at the start
TREE_TYPE = "frog_bt/Tree"
DATAGRAM_TYPE = "frog_bt/FrontendDatagram"
TICK_TYPE = "frog_bt/Tick"
CHUNK_SIZE = 256 * 1024  # bytes of uncompressed messages per chunk
FLUSH_EVERY = 2.0  # wall seconds between forced chunk flushes
HELD_LIMIT = 10_000  # messages held before the first /clock

# ------------------------------------------------------------------ JSON Schemas
# From the wire table's Structs (refs inlined: one self-contained schema per channel).


def _inline(node: Any, defs: dict[str, Any]) -> Any:
    if isinstance(node, dict):
        if "$ref" in node:
            return _inline(defs[node["$ref"].rsplit("/", 1)[1]], defs)
        return {k: _inline(v, defs) for k, v in node.items() if k != "$defs"}
    if isinstance(node, list):
        return [_inline(v, defs) for v in node]
    return node


def struct_schema(types: Any, title: str) -> dict[str, Any]:
    """The JSON schema of a Struct type (or a union of them), refs inlined."""
    schema = msgspec.json.decode(msgspec.json.encode(msgspec.json.schema(types)))  # as JSON
    return {**_inline(schema, schema.get("$defs", {})), "title": title}


def _datagram_schema() -> dict[str, Any]:
    """Every front-end message's fields in one object: a datagram is one of them."""
    props: dict[str, Any] = {
        "type": {"type": "string", "description": "command, event or ack (CONTRACT §2)"},
        "seq": {"type": "integer", "minimum": 0}}
    for cls in (*COMMANDS.values(), *EVENTS.values()):
        props.update(struct_schema(cls, cls.type).get("properties", {}))
    return {"type": "object", "title": DATAGRAM_TYPE, "properties": props,
            "required": ["type", "seq"]}


SCHEMAS: dict[str, dict[str, Any]] = {
    **{name: struct_schema(codec.wire, name) for name, codec in ROS_TYPES.items()},
    DATAGRAM_TYPE: _datagram_schema(),
    TREE_TYPE: {"type": "object", "title": TREE_TYPE, "properties": {
        "format": {"type": "string"}, "file": {"type": "string"},
        "xml": {"type": "string", "description": "the tree (Groot2 opens it)"}}},
    BLAME_TYPE: {"type": "object", "title": BLAME_TYPE, "properties": {
        "channel": {"type": "string", "description": "ROS topic or front-end message type"},
        "node": {"type": "string", "description": "the tree node that sent it"}}},
    TICK_TYPE: {"type": "object", "title": TICK_TYPE, "properties": {
        "tick": {"type": "integer"},
        "status": {"enum": ["INVALID", "RUNNING", "SUCCESS", "FAILURE"]}}},
}


def to_ns(t: float) -> int:
    """Clock seconds to integer nanoseconds; :func:`from_ns` gives ``t`` back exactly for
    any epoch time (float spacing there is far above a nanosecond)."""
    whole = math.floor(t)
    return whole * 1_000_000_000 + round((t - whole) * 1e9)


def from_ns(ns: int) -> float:
    """Integer nanoseconds to clock seconds (the float :func:`to_ns` was given)."""
    whole, frac = divmod(ns, 1_000_000_000)
    return whole + frac / 1e9


def _dumps(msg: Any) -> bytes:
    return json.dumps(msg, separators=(",", ":")).encode()


def _raw(msg: Any) -> bytes:
    """A received ``msg`` as JSON bytes: as it came (raw) when it is raw JSON."""
    return bytes(msg) if isinstance(msg, bytes | msgspec.Raw) else _dumps(msg)


Queued = tuple[int, int, bytes, int]  # channel id, log time (ns), data, sequence


def _write_queued(writer: Writer, queue: list[Queued]) -> None:
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
    :meth:`close` finishes it. A write error is logged once and stops the
    recording; it never reaches the tick path.
    """

    def __init__(self, path: Path, *, chunk_size: int = CHUNK_SIZE,
                 flush_every: float = FLUSH_EVERY) -> None:
        self.path = Path(path)
        self._stream: IO[bytes] = open(self.path, "wb")  # noqa: SIM115 - closed by _finish
        compression = CompressionType.NONE
        try:
            import lz4.frame  # noqa: F401 - optional, chosen only when installed

            compression = CompressionType.LZ4
        except ImportError:
            pass
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=compression)
        self._writer.start(profile="", library=f"frog-bt {__version__}")
        # Messages wait in _incoming until the event loop's current callback (a tick, an
        # input) is over, so that a tick pays a list append per message, not an MCAP
        # record each; _queue holds them stamped, for the writer (and the finalizer).
        self._incoming: list[tuple[int, float | None, bytes]] = []
        self._queue: list[Queued] = []
        self._drain_scheduled = False
        self._finalizer = weakref.finalize(self, _finish, self._writer, self._stream,
                                           self._queue)
        self._flush_every = flush_every
        self._flushed_at = time.monotonic()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[int, int] = {}
        self._last_ns = 0
        self._held: list[tuple[int, bytes]] = []
        self._ready: Callable[[], bool] = lambda: True
        self._clock_topic: str | None = None
        self.messages = 0
        self.dropped = 0  # held before the first /clock beyond HELD_LIMIT
        self.closed = False

    # ------------------------------------------------------------ wiring

    def attach(self, executive: Any) -> None:
        """Register every channel and hook the executive's wire and core taps."""
        site = executive.site
        for role, topic in (*INPUTS.items(), *OUTPUTS.items()):
            self.channel(site.topic(role), topic.type)
        if executive.sim_time:
            self._clock_topic = CLOCK.name
            self.channel(CLOCK.name, CLOCK.type)
        self.channel(FRONTEND_IN, DATAGRAM_TYPE)
        self.channel(FRONTEND_OUT, DATAGRAM_TYPE)
        self.channel(TICK, TICK_TYPE)
        self.channel(BLAME, BLAME_TYPE)
        clock = executive.clock
        self._ready = lambda: bool(clock.ready)
        self._write_tree(executive)
        executive.wire.ros_in.append(self.on_ros_in)
        executive.taps.ros_out.append(self.on_ros_out)
        executive.wire.datagram.append(self.on_datagram)
        executive.taps.tick.append(self.on_tick)
        executive.taps.blame.append(self.on_blame)

    def channel(self, topic: str, type_: str) -> int:
        """The channel id of ``topic``, registering it (and its schema) on first use."""
        cid = self._channels.get(topic)
        if cid is None:
            sid = self._schemas.get(type_)
            if sid is None:
                schema = SCHEMAS.get(type_, {"type": "object"})
                sid = self._writer.register_schema(type_, "jsonschema", _dumps(schema))
                self._schemas[type_] = sid
            cid = self._writer.register_channel(topic, "json", sid)
            self._channels[topic] = cid
        return cid

    # ------------------------------------------------------------ taps (tick path: keep cheap)

    def on_ros_in(self, t: float, topic: str, msg: Any) -> None:
        cid = self._channels.get(topic)
        if cid is None:
            cid = self.channel(topic, "unknown")
        data = _raw(msg)
        if topic == self._clock_topic:
            try:  # /clock is seen before the clock takes it: stamp it with its own time
                clock = CLOCK.codec.decode(data)
            except DecodeError:
                pass
            else:
                self._write(cid, max(t, clock) if self._ready() else clock, data)
                return
        self._write(cid, t if self._ready() else None, data)

    def on_ros_out(self, t: float, topic: str, msg: Any) -> None:
        self._write(self._channels.get(topic) or self.channel(topic, "unknown"), t, _dumps(msg))

    def on_datagram(self, direction: str, data: bytes, t: float) -> None:
        topic = FRONTEND_IN if direction == "in" else FRONTEND_OUT
        cid = self._channels.get(topic) or self.channel(topic, DATAGRAM_TYPE)
        self._write(cid, t if self._ready() else None, bytes(data))

    def _write_tree(self, executive: Any) -> None:
        """The tree that runs, so that a recording explains itself without the files."""
        from frog_bt.tools.btcpp import tree_xml

        tree = getattr(getattr(executive, "core", None), "tree", None)
        if tree is None:
            return
        tree_file = Path(tree.file)
        try:
            xml = tree_xml(tree_file, executive.site)
        except Exception as exc:
            log.info("recording without the tree's XML: %s", exc)
            return
        self._write(self.channel(TREE, TREE_TYPE), None, _dumps(
            {"format": "BehaviorTree.CPP v4", "file": str(tree_file), "xml": xml}))

    def on_blame(self, t: float, channel: str, node: str) -> None:
        self._write(self._channels.get(BLAME) or self.channel(BLAME, BLAME_TYPE), t,
                    _dumps({"channel": channel, "node": node}))

    def on_tick(self, core: Any) -> None:
        status = core.bt.root.status.name
        self._write(self._channels.get(TICK) or self.channel(TICK, TICK_TYPE), core.clock.now(),
                    b'{"tick":%d,"status":"%s"}' % (core.ticks, status.encode()))

    # ------------------------------------------------------------ writing

    def _write(self, cid: int, t: float | None, data: bytes) -> None:
        """Take a message (``t`` None: before the clock has a time); it is stamped and
        written once the event loop's current callback is over (at once without a loop)."""
        if self.closed:
            return
        self._incoming.append((cid, t, data))
        if not self._drain_scheduled:
            try:
                loop = asyncio.get_running_loop()
            except RuntimeError:  # no event loop: write now
                self._drain()
                return
            self._drain_scheduled = True
            loop.call_soon(self._drain)

    def _stamp(self) -> None:
        """Give the incoming messages their log times and sequence numbers, in order."""
        incoming, self._incoming = self._incoming, []
        for cid, t, data in incoming:
            if t is None:  # before the first /clock: no time yet
                if len(self._held) < HELD_LIMIT:
                    self._held.append((cid, data))
                else:
                    self.dropped += 1
                continue
            ns = max(to_ns(t), self._last_ns)
            if self._held:
                held, self._held = self._held, []
                for held_cid, held_data in held:
                    self._add(held_cid, ns, held_data)
            self._add(cid, ns, data)
            self._last_ns = ns

    def _add(self, cid: int, ns: int, data: bytes) -> None:
        seq = self._sequence.get(cid, 0)
        self._sequence[cid] = seq + 1
        self._queue.append((cid, ns, data, seq & 0xFFFFFFFF))
        self.messages += 1

    def _drain(self) -> None:
        """Write the queued messages, in order; flush a chunk every ``flush_every`` s."""
        self._drain_scheduled = False
        if self.closed:
            return  # close() wrote them
        try:
            self._stamp()
            _write_queued(self._writer, self._queue)
            now = time.monotonic()
            if now - self._flushed_at >= self._flush_every:
                self._flushed_at = now
                self._writer.flush()
        except Exception as exc:  # disk full, ...: stop recording, never stop the robot
            log.error("recording to %s stopped: %s", self.path, exc)
            self._queue.clear()
            self.close()

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
            log.warning("recording: %d messages before the first /clock were never stamped",
                        len(self._held))
            self._held = []
        if self.dropped:
            log.warning("recording: %d messages before the first /clock dropped", self.dropped)
        self._finalizer()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
