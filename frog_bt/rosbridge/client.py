"""Asyncio rosbridge client: a thin shell around the sans-I/O :class:`Session`.

The :class:`~frog_bt.rosbridge.protocol.Session` decides what to send and
when; this module only moves frames between it and a WebSocket
(``websockets.asyncio.client``), reconnects, and turns inbound ``publish`` ops
into typed values with :data:`frog_bt.model.ros.ROS_TYPES`.

* ``advertise``/``subscribe``/``publish``/... are plain synchronous calls, O(1)
  and never blocking, so behaviour-tree leaves may call them inside a tick.
  A frame is written to the socket at once, while the connection takes it
  without waiting (:meth:`RosbridgeClient._write_waiting`): the command a tick
  sends leaves while the tick goes on, not after the tick and whatever the event
  loop has queued behind it (the observers, telemetry). What the connection does
  not take at once waits in an outbox drained, in order, by one writer task per
  connection. While the link is down publishes wait in the Session's bounded
  queue (oldest dropped and counted).
* The connect loop reconnects for ever with capped exponential backoff and,
  on every connection, sends ``Session.on_connected`` frames first (auth,
  advertise, subscribe, queued publishes).
* Bad input never stops the receive loop: malformed frames and messages are
  counted per topic in :attr:`RosbridgeClient.stats` and logged at most once
  per topic per :data:`frog_bt.warning_limit.WARN_INTERVAL` seconds.

Not thread-safe: call every method from the event loop's thread.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractAsyncContextManager
from dataclasses import replace
from typing import Any

from websockets.asyncio.client import ClientConnection, connect
from websockets.exceptions import ConnectionClosed, InvalidURI, WebSocketException
from websockets.protocol import State
from websockets.uri import parse_uri

from frog_bt.errors import DecodeError
from frog_bt.model.ros import ROS_TYPES
from frog_bt.rosbridge.link import ClientStats, LinkState
from frog_bt.rosbridge.protocol import (
    MAX_FRAME_BYTES,
    OtherOp,
    Publish,
    Session,
    Status,
    decode_frame,
)
from frog_bt.warning_limit import WarningLimiter

__all__ = ["FRAME_TOPIC", "ClientStats", "LinkState", "RosbridgeClient", "backoff_delays"]

log = logging.getLogger(__name__)
_OPEN = State.OPEN

FRAME_TOPIC = "<frame>"  # stats/warning key for frames too broken to name a topic
# A frame above decode_frame's guard is counted as malformed; only far larger
# ones make websockets drop the connection (which would then loop on reconnect).
_MAX_WS_MESSAGE = 4 * MAX_FRAME_BYTES


# Opens one connection to a URL, as an async context manager: websockets' ``connect`` by
# default, or an in-memory wire's (frog_bt.rosbridge.memory) in tests.
Connect = Callable[[str], AbstractAsyncContextManager[Any]]


def _websocket(url: str) -> AbstractAsyncContextManager[ClientConnection]:
    return connect(url, proxy=None, max_size=_MAX_WS_MESSAGE, open_timeout=10, close_timeout=2)


class RosbridgeClient:
    """rosbridge v2 client with reconnect; see the module docstring.

    ``on_message(topic, value)`` gets the typed value of every well-formed
    message on a subscribed topic; ``on_input(topic, value, msg)`` gets every message on a
    subscribed topic, well-formed or not (``value`` None: it did not decode, and was
    counted), with its ``msg`` as received; ``on_link(state)`` gets the new
    :class:`LinkState` each time the link goes up or down. Exceptions from
    either callback are logged and otherwise ignored.

    The auth frame (sent first on each connection when ``secret`` is set) is
    stamped with the wall clock: rosauth compares it with the server's time.

    ``connect`` opens the connections (default: a WebSocket to ``url``); a
    :class:`~frog_bt.rosbridge.memory.MemoryWire`'s ``connect`` runs the same client
    with no socket.
    """

    def __init__(
        self,
        url: str,
        *,
        secret: str | None = None,
        queue_limit: int = 1000,
        backoff_initial: float = 0.25,
        backoff_max: float = 5.0,
        stable_after: float = 5.0,
        on_message: Callable[[str, Any], None] | None = None,
        on_link: Callable[[LinkState], None] | None = None,
        on_raw: Callable[[str, Any], None] | None = None,
        on_input: Callable[[str, object, Any], None] | None = None,
        connect: Connect | None = None,
    ) -> None:
        if connect is None:
            try:
                parse_uri(url)
            except InvalidURI as exc:
                raise ValueError(f"rosbridge URL {url!r}: {exc}") from None
        if queue_limit < 1:
            raise ValueError(f"queue_limit must be >= 1, got {queue_limit}")
        if not 0 < backoff_initial <= backoff_max:
            raise ValueError(
                f"need 0 < backoff_initial <= backoff_max, got {backoff_initial}, {backoff_max}"
            )
        self.url = url
        self.backoff_initial = backoff_initial
        self.backoff_max = backoff_max
        # A connection that ends sooner, with nothing received on it, was not a success (a
        # refused auth is a close right after the handshake): the backoff goes on growing.
        self.stable_after = stable_after
        self.on_message = on_message
        self.on_link = on_link
        self.on_raw = on_raw  # (topic, msg JSON) of every publish on a subscribed topic
        self.on_input = on_input
        self._connect: Connect = connect or _websocket
        self.session = Session(queue_limit=queue_limit, secret=secret)
        self.stats = ClientStats()
        self._link = LinkState(connected=False, since=time.monotonic())
        self._throttle = WarningLimiter(logger=log)
        self._outbox: deque[str] = deque()  # frames for the current connection, in order
        self._writing = False  # the writer task is sending the outbox's first frame
        self._held = False  # publishes wait for release() (hold: the executive's tick)
        self._wake = asyncio.Event()  # outbox became non-empty
        self._drained = asyncio.Event()  # the writer found the outbox empty
        self._up = asyncio.Event()  # set while connected
        self._ever_connected = False
        self._closing = False
        self._loop_task: asyncio.Task[None] | None = None
        self._run_task: asyncio.Task[None] | None = None
        self._ws: Any = None  # the current connection (ClientConnection over a socket)
        self._heard = 0

    # ------------------------------------------------------------ program side

    @property
    def link(self) -> LinkState:
        return self._link

    @property
    def queued(self) -> int:
        """Publishes waiting for the link to come back."""
        return self.session.queued

    def advertise(self, topic: str, type: str) -> None:
        self._enqueue(self.session.advertise(topic, type))

    def unadvertise(self, topic: str) -> None:
        self._enqueue(self.session.unadvertise(topic))

    def subscribe(
        self, topic: str, type: str, throttle_rate: int = 0, queue_length: int = 0
    ) -> None:
        """Subscribe; messages arrive decoded by ``ROS_TYPES[type]``.

        Raises ValueError for a type with no decoder (a programming error).
        """
        if type not in ROS_TYPES:
            raise ValueError(f"subscribe {topic!r}: no decoder for type {type!r}")
        self._enqueue(self.session.subscribe(topic, type, throttle_rate, queue_length))

    def unsubscribe(self, topic: str) -> None:
        self._enqueue(self.session.unsubscribe(topic))

    def publish(self, topic: str, msg: Any, urgent: bool = False) -> None:
        """Send now, or queue while the link is down. Never blocks. While held
        (:meth:`hold`), the frame waits for :meth:`release`, unless ``urgent`` (a goal):
        then it goes at once, with those waiting before it, in one write.

        Raises ValueError for a topic never advertised or a message that is not
        finite JSON (NaN, Infinity): programming errors, caught at the call.
        """
        dropped = self.session.dropped
        self._enqueue(self.session.publish(topic, msg), urgent)
        self._note_dropped(dropped)

    def hold(self) -> None:
        """Keep what is published from now in the outbox, until :meth:`release` or an
        urgent publish: the executive holds during a tick, so that its commands reach the
        robot in one write (one wake-up of the robot's server, not one per command)."""
        self._held = True

    def release(self) -> None:
        """Write what :meth:`hold` kept, in order, in one write where the connection
        takes it now (the writer task sends the rest)."""
        self._held = False
        if self._outbox and self._write_waiting():
            self._wake.set()

    def leave(self) -> None:
        """Unsubscribe from every topic and unadvertise every one, so that the server is
        left tidy (only while connected: nothing is queued for a later connection)."""
        if self._link.connected:
            for topic in list(self.session.subscriptions):
                self.unsubscribe(topic)
            for topic in list(self.session.advertised):
                self.unadvertise(topic)

    # ------------------------------------------------------------ lifecycle

    def start(self) -> asyncio.Task[None]:
        """Run the connect loop in a task (idempotent); returns the task."""
        if self._run_task is None:
            self._run_task = asyncio.get_running_loop().create_task(
                self.run(), name=f"rosbridge {self.url}"
            )
        return self._run_task

    async def run(self) -> None:
        """Connect, serve and reconnect until :meth:`close`; then return."""
        if self._loop_task is not None:
            raise RuntimeError("RosbridgeClient.run() already called")
        if self._closing:
            return  # closed before the loop began (start() then close() at once)
        task = asyncio.get_running_loop().create_task(self._connect_loop())
        self._loop_task = task
        try:
            await task
        except asyncio.CancelledError:
            current = asyncio.current_task()
            if current is not None and current.cancelling():
                raise  # run() itself was cancelled (the loop task with it)
            # otherwise close() cancelled the loop: a normal end

    async def flush(self, timeout: float) -> bool:
        """Wait (at most ``timeout`` wall seconds) until every queued frame is written.

        True when the outbox drained; False on timeout or while disconnected
        (frames then stay queued for the next connection).
        """
        if self._outbox and self._link.connected:
            self._drained.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self._drained.wait(), timeout)
        return not self._outbox

    async def close(self) -> None:
        """Stop the connect loop and close the connection (code 1000); final."""
        self._closing = True
        self._throttle.flush()  # the warnings held back since their last line, told once
        ws = self._ws
        if ws is not None:
            # A clean close handshake first: cancelling the loop inside ``connect``
            # would close with 1011 (internal error), which a server may log as one.
            with contextlib.suppress(Exception):
                await asyncio.wait_for(ws.close(), 2)
        for task in (self._loop_task, self._run_task):
            if task is not None and not task.done():
                if task is asyncio.current_task():
                    raise RuntimeError("close() called from inside the client's own task")
                if task is self._loop_task:
                    task.cancel()
                await asyncio.wait({task})

    async def wait_connected(self, timeout: float | None = None) -> bool:
        """True once connected; False if ``timeout`` seconds pass first."""
        if self._link.connected:
            return True
        try:
            async with asyncio.timeout(timeout):
                await self._up.wait()
        except TimeoutError:
            return False
        return True

    # ------------------------------------------------------------ connect loop

    async def _connect_loop(self) -> None:
        # Backoff waits on real time (asyncio.sleep), never on the executive's
        # Clock: under --sim-time the link IS the source of /clock, so a sim
        # clock would stand still exactly while the link is down.
        delays = backoff_delays(self.backoff_initial, self.backoff_max)
        attempt = 1
        while True:
            error: str | None = None
            up_at: float | None = None
            delay = 0.0
            try:
                async with self._connect(self.url) as ws:
                    up_at = time.monotonic()
                    self._on_up(ws)
                    error = await self._serve(ws)
                    if self._closing:
                        error = None  # close(): not an error
            except asyncio.CancelledError:
                error = None  # close(): not an error
                raise
            except (OSError, TimeoutError, WebSocketException) as exc:
                error = _describe(exc)
            except Exception as exc:  # a bug; keep the link alive regardless
                error = _describe(exc)
                log.exception("rosbridge %s: unexpected error", self.url)
            finally:
                self._ws = None
                # A connection worked if the server said anything on it, or if it stayed up.
                stable = up_at is not None and (
                    self._heard > 0 or time.monotonic() - up_at >= self.stable_after
                )
                if stable:
                    delays = backoff_delays(self.backoff_initial, self.backoff_max)  # reset
                    attempt = 1
                else:
                    attempt += 1
                delay = next(delays)
                # A server refuses an auth by closing at once, having sent nothing.
                refused = (
                    up_at is not None
                    and not stable
                    and not self._closing
                    and self.session.secret is not None
                )
                self._on_down(error, attempt, time.monotonic() + delay, refused)
            if self._closing:
                return
            await asyncio.sleep(delay)

    async def _serve(self, ws: Any) -> str:
        """Run reader and writer until the connection ends; say why it ended."""
        reader = asyncio.create_task(self._read_loop(ws))
        writer = asyncio.create_task(self._write_loop(ws))
        try:
            done, _ = await asyncio.wait((reader, writer), return_when=asyncio.FIRST_COMPLETED)
        finally:
            for task in (reader, writer):
                task.cancel()
            await asyncio.wait((reader, writer))
        for task in done:
            exc = task.exception()
            if exc is not None and not isinstance(exc, ConnectionClosed):
                raise exc
        code = ws.close_code if ws.close_code is not None else 1006
        return f"connection closed (code {code}{', ' + ws.close_reason if ws.close_reason else ''})"

    async def _read_loop(self, ws: Any) -> None:
        async for frame in ws:
            self._on_frame(frame)

    async def _write_loop(self, ws: Any) -> None:
        out = self._outbox
        while True:
            if not out:
                self._drained.set()
                self._wake.clear()
                await self._wake.wait()
                continue
            # Peek, send, then pop: a frame whose send failed is still in the
            # outbox when the link goes down, and publishes there are re-queued.
            # (_writing: write_now leaves the outbox alone until it is popped.)
            self._writing = True
            try:
                await ws.send(out[0])
            finally:
                self._writing = False
            out.popleft()
            self.stats.sent += 1

    def _enqueue(self, frames: list[str], urgent: bool = True) -> None:
        if frames:
            self._outbox.extend(frames)
            if (urgent or not self._held) and self._write_waiting():
                self._wake.set()  # the writer task sends the rest

    def _write_waiting(self) -> bool:
        """Write the frames waiting in the outbox, in order, now, in one write, as far as
        the connection takes them without waiting (:func:`_write_now`); none while the
        writer task is sending one (it pops it when done). True when some are left."""
        ws, out = self._ws, self._outbox
        if ws is not None and not self._writing and self._link.connected and out:
            written = _write_now(ws, out)
            for _ in range(written):
                out.popleft()
            self.stats.sent += written
        return bool(out)

    def _on_up(self, ws: Any) -> None:
        with contextlib.suppress(Exception):  # addresses only feed the auth MAC
            self.session.client_addr = str(ws.local_address[0])
            self.session.dest_addr = str(ws.remote_address[0])
        self._ws = ws
        self._heard = 0  # frames received on this connection
        self._outbox.clear()
        self._enqueue(self.session.on_connected(time.time()))
        if self._ever_connected:
            self.stats.reconnects += 1
        self._ever_connected = True
        self._up.set()
        log.info("rosbridge %s: connected", self.url)
        self._set_link(True, None)

    def _on_down(
        self,
        error: str | None,
        attempt: int = 0,
        retry_at: float | None = None,
        refused: bool = False,
    ) -> None:
        pending = list(self._outbox)
        self._outbox.clear()
        self.session.on_disconnected()
        self._up.clear()
        dropped = self.session.dropped
        for text in pending:  # publishes that never made it: back into the Session's queue
            self._requeue(text)
        self._note_dropped(dropped)
        if self._closing:
            retry_at = None
        if refused:
            error = f"{error or 'closed'}, right after connecting: authentication refused?"
        if self._link.connected:
            if error is None:
                log.info("rosbridge %s: closed", self.url)
            else:
                log.warning("rosbridge %s: link lost: %s", self.url, error)
            self._set_link(False, error, attempt, retry_at, refused)
        elif error is not None:
            self.stats.connect_failures += 1
            self._link = replace(
                self._link, last_error=error, attempt=attempt, retry_at=retry_at, refused=False
            )
            self._warn("connect", "rosbridge %s: cannot connect: %s", self.url, error)

    def _requeue(self, text: str) -> None:
        frame = json.loads(text)
        if frame.get("op") != "publish":
            return  # advertise/subscribe/auth are regenerated by on_connected
        with contextlib.suppress(ValueError):  # unadvertised meanwhile: drop it
            self.session.publish(frame["topic"], frame["msg"])

    def _set_link(
        self,
        connected: bool,
        error: str | None,
        attempt: int = 0,
        retry_at: float | None = None,
        refused: bool = False,
    ) -> None:
        self._link = LinkState(
            connected, time.monotonic(), self.stats.reconnects, error, attempt, retry_at, refused
        )
        if self.on_link is not None:
            try:
                self.on_link(self._link)
            except Exception:
                log.exception("rosbridge %s: on_link callback failed", self.url)

    # ------------------------------------------------------------ inbound

    def _on_frame(self, frame: str | bytes) -> None:
        self.stats.received += 1
        self._heard += 1
        try:
            event = decode_frame(frame)
        except DecodeError as exc:
            self._malformed(FRAME_TOPIC, f"malformed frame: {exc}")
            return
        if isinstance(event, Status):
            log.debug("rosbridge status %s: %s (id %s)", event.level, event.msg, event.id)
            return
        if isinstance(event, OtherOp):
            self.stats.ignored += 1
            log.debug("rosbridge: ignoring op %r", event.op[:80])
            return
        assert isinstance(event, Publish)
        sub = self.session.subscriptions.get(event.topic)
        if sub is None:
            self.stats.ignored += 1
            log.debug("rosbridge: publish on %s, which is not subscribed", event.topic[:80])
            return
        if self.on_raw is not None:
            self.on_raw(event.topic, event.msg)
        value: object = None
        try:
            value = ROS_TYPES[sub.type].decode(event.msg)
        except DecodeError as exc:
            self._malformed(event.topic, f"malformed {sub.type} on {event.topic}: msg.{exc}")
        try:
            if self.on_input is not None:
                self.on_input(event.topic, value, event.msg)
            elif self.on_message is not None and value is not None:
                self.on_message(event.topic, value)
        except Exception:
            held = self._throttle.allow(f"on_message {event.topic}")
            if held is not None:
                log.exception("rosbridge: on_message(%s) failed%s", event.topic, _held(held))

    def _malformed(self, topic: str, text: str) -> None:
        self.stats.malformed += 1
        by_topic = self.stats.malformed_by_topic
        by_topic[topic] = by_topic.get(topic, 0) + 1
        self._warn(topic, "rosbridge: %s", text)

    def _note_dropped(self, before: int) -> None:
        self.stats.dropped = self.session.dropped
        if self.session.dropped > before:
            self._warn(
                "queue",
                "rosbridge %s: link down, publish queue full (%d), %d dropped in all",
                self.url,
                self.session.queue_limit,
                self.session.dropped,
            )

    def _warn(self, key: str, fmt: str, *args: Any) -> None:
        held = self._throttle.allow(key)
        if held is not None:
            log.warning(fmt + "%s", *args, _held(held))


def _write_now(ws: Any, texts: Iterable[str]) -> int:
    """Write text frames to ``ws`` now, in order, in one write, when it can take them
    without waiting; how many were written (0: the writer task sends them, in order).

    What websockets' ``send`` does for each text frame, minus its waits: the frames go to
    the sans-I/O protocol (``ws.protocol``) and their bytes to the transport together
    (one ``writelines``: one system call, one segment where they fit), only while the
    connection is open, no fragmented message is being sent and the transport's buffer
    is empty (so no backpressure is skipped). A connection of another kind (a test's
    in-memory wire, a websockets without these) always says 0."""
    if not isinstance(ws, ClientConnection):
        return 0
    written = 0
    try:
        if (
            ws.protocol.state is not _OPEN
            or ws.send_in_progress is not None
            or ws.transport.get_write_buffer_size()
            or ws.protocol.close_expected()
        ):
            return 0
        for text in texts:
            ws.protocol.send_text(text.encode())
            written += 1
    except Exception:  # not as this websockets has it: leave the frames to the writer
        if not written:
            return 0
    try:
        # text frames only, on an open connection not closing: no end of stream (b"")
        # among them, which websockets' send_data would turn into write_eof
        ws.transport.writelines(ws.protocol.data_to_send())
    except Exception as exc:  # written to the protocol: the link is broken, as send says
        ws.set_connection_exc(exc)
        ws.transport.abort()
    return written


def backoff_delays(initial: float, maximum: float) -> Iterator[float]:
    """``initial``, doubling each time, capped at ``maximum``; never ends."""
    delay = initial
    while True:
        yield delay
        delay = min(delay * 2, maximum)


def _held(count: int) -> str:
    return f" ({count} more suppressed)" if count else ""


def _describe(exc: BaseException) -> str:
    text = str(exc)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
