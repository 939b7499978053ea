"""What every section of ``scripts/bench`` shares: statistics, synthetic sites and scenarios,
process memory, and the fake robot (rosbridge server) and fake front end (UDP peer).

Nothing here asserts anything: the sections measure and report; budgets are read off
the table that ``scripts/bench`` prints. Every socket is on the loopback interface.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import os
import socket
import struct
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parent.parent
SCRIPTS = ROOT / "scripts"
SITE_FILE = ROOT / "config" / "site.yaml"
LOOPBACK = "127.0.0.1"
FROG_BT = Path(sys.executable).parent / "frog-bt"  # the console script of this environment

# ------------------------------------------------------------------ statistics


def percentile(sorted_values: Sequence[float], q: float) -> float:
    """Nearest-rank percentile (``q`` in 0..1) of an already sorted list."""
    if not sorted_values:
        return math.nan
    rank = max(1, math.ceil(q * len(sorted_values)))
    return sorted_values[min(rank, len(sorted_values)) - 1]


def summary_us(samples_ns: Iterable[int]) -> dict[str, float]:
    """n, p50, p99, mean and max of nanosecond samples, in microseconds."""
    values = sorted(samples_ns)
    if not values:
        return {"n": 0}
    return {
        "n": len(values),
        "p50_us": percentile(values, 0.50) / 1e3,
        "p99_us": percentile(values, 0.99) / 1e3,
        "mean_us": sum(values) / len(values) / 1e3,
        "max_us": values[-1] / 1e3,
    }


def summary(values: Iterable[float]) -> dict[str, float]:
    ordered = sorted(values)
    if not ordered:
        return {"n": 0}
    return {
        "n": len(ordered),
        "p50": percentile(ordered, 0.5),
        "min": ordered[0],
        "max": ordered[-1],
    }


# ------------------------------------------------------------------ memory


def memory_kb(pid: int | str = "self") -> dict[str, int]:
    """Resident set (``rss_kb``) and its peak (``hwm_kb``) of a process, from /proc."""
    out: dict[str, int] = {}
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(("VmRSS:", "VmHWM:")):
                    key = "rss_kb" if line.startswith("VmRSS") else "hwm_kb"
                    out[key] = int(line.split()[1])
    except OSError:
        if pid == "self":  # not Linux: the peak is what resource can tell
            import resource

            peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
            out = {"rss_kb": peak, "hwm_kb": peak}
    return out


# ------------------------------------------------------------------ sites and scenarios


def synthetic_site(
    stops: int,
    directory: Path,
    *,
    flags: dict[str, Any] | None = None,
    over: dict[str, Any] | None = None,
) -> Path:
    """A copy of ``config/site.yaml`` whose tour has ``stops`` synthetic stops.

    The stops ``S000``, ``S001``, ... lie on a lattice 8 m apart (rows of ten, driven
    back and forth) next to the courtyard, so a drive between two takes about 13 s
    at the simulator's 0.6 m/s. Each takes the flags of the real tour's stop in the
    same position modulo its length (face stream, projector, content, follower
    check), or ``flags`` for all when given. The dock and POI0 are kept.
    """
    data = yaml.safe_load(SITE_FILE.read_text(encoding="utf-8"))
    tour = data["tour"]
    pattern = [{k: v for k, v in s.items() if k != "poi"} for s in tour["stops"]]
    pois = {k: v for k, v in data["pois"].items() if k in (tour["dock"], tour["recruit_at"])}
    new_stops = []
    for i in range(stops):
        row, col = divmod(i, 10)
        col = col if row % 2 == 0 else 9 - col
        name = f"S{i:03d}"
        pois[name] = {
            "x": 60.0 + 8.0 * col,
            "y": 45.0 + 8.0 * row,
            "z": 0.0,
            "w": 1.0,
            "name": f"Synthetic stop {i}",
        }
        new_stops.append(
            {"poi": name, **(flags if flags is not None else pattern[i % len(pattern)])}
        )
    data["pois"] = pois
    data["variants"] = {}
    tour["stops"] = new_stops
    from frog_bt.sim.scenario import merge

    data = merge(data, over or {})
    path = Path(directory) / f"site-{stops}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def scenario(over: dict[str, Any] | None = None) -> Any:
    """The simulator's default scenario with ``over`` on top, validated."""
    from frog_bt.sim import scenario_from

    return scenario_from("default", over)


def small_log(sim: Any) -> None:
    """Keep only the simulator's latest 2,000 traffic records (200,000 by default).

    The simulator runs in the same process as the executive in some sections; its
    log of every message would otherwise give the garbage collector hundreds of
    thousands of objects to scan that the executive alone never has.
    """
    from frog_bt.sim.traffic import MessageLog

    sim.log = MessageLog(maxlen=2000)


def free_port(kind: int = socket.SOCK_DGRAM) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind((LOOPBACK, 0))
        return int(s.getsockname()[1])


# ------------------------------------------------------------------ the fake robot


# The kernel's receive time of what a socket reads (Linux, socket(7)): a datagram's with
# SO_TIMESTAMPNS, a TCP stream's (its last segment read) with SO_TIMESTAMPING.
SO_TIMESTAMPNS = 35
SO_TIMESTAMPING = 37
RX_SOFTWARE = 0x8 | 0x10  # SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE


class StampingSocket:
    """A transport's socket that reads with ``recvmsg`` and keeps, in ``stamp``, when the
    kernel received what it read (``perf_counter_ns`` clock), and in ``read`` when this
    process read it. With these the ruler stops where the bytes reach this process's
    socket, before this process is even scheduled to read them: the fake robot's own
    wake-up and work are not the executive's reaction."""

    def __init__(self, sock: socket.socket, option: int, value: int) -> None:
        sock.setsockopt(socket.SOL_SOCKET, option, value)
        self._sock = sock
        self.stamp = 0
        self.read = 0

    def __getattr__(self, name: str) -> Any:
        return getattr(self._sock, name)

    def _recv(self, size: int) -> tuple[bytes, Any]:
        data, ancillary, _, addr = self._sock.recvmsg(size, socket.CMSG_SPACE(48))
        real, self.read = time.time_ns(), time.perf_counter_ns()
        self.stamp = self.read
        for level, kind, raw in ancillary:
            if level == socket.SOL_SOCKET and kind in (SO_TIMESTAMPNS, SO_TIMESTAMPING):
                sec, nsec = struct.unpack_from("qq", raw)
                if sec or nsec:
                    self.stamp = min(self.read, sec * 1_000_000_000 + nsec - (real - self.read))
        return data, addr

    def recv(self, size: int) -> bytes:
        return self._recv(size)[0]

    def recvfrom(self, size: int) -> tuple[bytes, Any]:
        return self._recv(size)


def stamp_transport(transport: Any, option: int, value: int) -> StampingSocket | None:
    """Make an asyncio selector transport read through a :class:`StampingSocket`; None
    where it cannot (not Linux, another kind of transport): read times then."""
    sock = getattr(transport, "_sock", None)
    if not sys.platform.startswith("linux") or not isinstance(sock, socket.socket):
        return None
    try:
        stamping = StampingSocket(sock, option, value)
    except OSError:
        return None
    transport._sock = stamping
    return stamping


def stamped_connection() -> Any:
    """A websockets server connection that stamps each data message (``stamps``, in
    order) with the kernel's receive time of the bytes that complete it
    (:class:`StampingSocket`; the time they were read where that is not available), and
    keeps the read time too (``reads``)."""
    from collections import deque

    from websockets.asyncio.server import ServerConnection
    from websockets.frames import DATA_OPCODES, Frame

    class Stamped(ServerConnection):
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self.stamps: deque[int] = deque()
            self.reads: deque[int] = deque()
            self._received = self._read = 0
            self._stamping: StampingSocket | None = None

        def connection_made(self, transport: Any) -> None:
            self._stamping = stamp_transport(transport, SO_TIMESTAMPING, RX_SOFTWARE)
            super().connection_made(transport)

        def data_received(self, data: bytes) -> None:
            stamping = self._stamping
            if stamping is not None:
                self._received, self._read = stamping.stamp, stamping.read
            else:
                self._received = self._read = time.perf_counter_ns()
            super().data_received(data)

        def process_event(self, event: Any) -> None:
            if isinstance(event, Frame) and event.opcode in DATA_OPCODES and event.fin:
                self.stamps.append(self._received)
                self.reads.append(self._read)
            super().process_event(event)

    return Stamped


class FakeRosbridge:
    """A minimal rosbridge v2 server for one client at a time, with socket timestamps.

    Like rosbridge_server (tornado) it offers no permessage-deflate. It records what
    the client advertises and subscribes to, hands every ``publish`` from the client to
    ``on_publish(topic, msg, t_ns)`` with ``t_ns = perf_counter_ns()`` taken as the
    bytes that complete the frame come off the socket (:func:`stamped_connection`:
    before this process parses them, so its own work and scheduling do not count),
    and :meth:`publish` returns the same clock's time taken just before the frame is
    written.
    """

    def __init__(
        self,
        on_publish: Callable[[str, Any, int], None] | None = None,
        expect_subscriptions: int = 0,
    ) -> None:
        self.on_publish = on_publish
        self.expect = expect_subscriptions
        self.subscribed: dict[str, str] = {}
        self.ready = asyncio.Event()  # the current client subscribed to `expect` topics
        self.ready_ns = 0
        self.read_ns = 0  # when this process read the frame last handed to on_publish
        self.connections = 0
        self.ws: Any = None
        self.port = 0
        self._server: Any = None

    async def start(self) -> None:
        from websockets.asyncio.server import serve

        self._server = await serve(
            self._handle,
            LOOPBACK,
            0,
            compression=None,
            max_size=1 << 22,
            create_connection=stamped_connection(),
        )
        self.port = next(iter(self._server.sockets)).getsockname()[1]

    @property
    def url(self) -> str:
        return f"ws://{LOOPBACK}:{self.port}"

    async def stop(self) -> None:
        if self._server is not None:
            self._server.close(close_connections=True)
            await self._server.wait_closed()

    async def _handle(self, ws: Any) -> None:
        from websockets.exceptions import ConnectionClosed

        self.ws, self.subscribed = ws, {}
        self.ready.clear()
        self.connections += 1
        try:
            async for frame in ws:
                t = ws.stamps.popleft() if ws.stamps else time.perf_counter_ns()
                self.read_ns = ws.reads.popleft() if ws.reads else t
                obj = json.loads(frame)
                op = obj.get("op")
                if op == "publish":
                    if self.on_publish is not None:
                        self.on_publish(obj["topic"], obj["msg"], t)
                elif op == "subscribe":
                    self.subscribed[obj["topic"]] = obj.get("type", "")
                    if (
                        self.expect
                        and len(self.subscribed) >= self.expect
                        and not self.ready.is_set()
                    ):
                        self.ready_ns = t
                        self.ready.set()
        except ConnectionClosed:
            pass
        finally:
            if self.ws is ws:
                self.ws = None

    async def publish(self, topic: str, msg: Any) -> int:
        """Send one ``publish`` to the client; the time just before it is written."""
        return await self.send_text(
            json.dumps({"op": "publish", "topic": topic, "msg": msg}, separators=(",", ":"))
        )

    async def send_text(self, text: str) -> int:
        from websockets.exceptions import ConnectionClosed

        ws = self.ws
        t = time.perf_counter_ns()
        if ws is not None:
            with contextlib.suppress(ConnectionClosed):  # the client went: nothing to time
                await ws.send(text)
        return t


# ------------------------------------------------------------------ the fake front end


class FakeFrontend(asyncio.DatagramProtocol):
    """The content front end over UDP: acks commands, sends events, socket timestamps.

    ``on_command(message, t_ns)`` gets every new command, ``t_ns`` the kernel's
    receive time of its datagram (:class:`StampingSocket`; ``read_ns`` when this
    process read it); :meth:`send` returns the time just before an event is written.
    """

    def __init__(
        self, executive: tuple[str, int], on_command: Callable[[Any, int], None] | None = None
    ) -> None:
        from frog_bt.frontend.protocol import Endpoint
        from frog_bt.model.frontend import COMMANDS

        self.executive = executive
        self.on_command = on_command
        self.endpoint = Endpoint(executive[0], COMMANDS)
        self.transport: Any = None
        self.read_ns = 0
        self._stamping: StampingSocket | None = None

    async def open(self, port: int = 0) -> int:
        loop = asyncio.get_running_loop()
        self.transport, _ = await loop.create_datagram_endpoint(
            lambda: self, local_addr=(LOOPBACK, port)
        )
        self._stamping = stamp_transport(self.transport, SO_TIMESTAMPNS, 1)
        return int(self.transport.get_extra_info("sockname")[1])

    def datagram_received(self, data: bytes, addr: tuple[str, int]) -> None:
        stamping = self._stamping
        if stamping is not None:
            t, self.read_ns = stamping.stamp, stamping.read
        else:
            t = self.read_ns = time.perf_counter_ns()
        received = self.endpoint.receive(data, addr[0], time.monotonic())
        if received.reply is not None:
            self.transport.sendto(received.reply, addr)
        if received.message is not None and self.on_command is not None:
            self.on_command(received.message, t)

    def send(self, message: Any) -> int:
        data = self.endpoint.send(message, time.monotonic())
        t = time.perf_counter_ns()
        self.transport.sendto(data, self.executive)
        return t

    def close(self) -> None:
        if self.transport is not None:
            self.transport.close()


# ------------------------------------------------------------------ child processes


class Child:
    """A child process that speaks JSON lines on stdout and takes commands on stdin."""

    def __init__(self, proc: asyncio.subprocess.Process) -> None:
        self.proc = proc
        self.events: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
        self._reader = asyncio.ensure_future(self._read())

    @classmethod
    async def start(cls, *argv: str | Path, env: dict[str, str] | None = None) -> Child:
        proc = await asyncio.create_subprocess_exec(
            *map(str, argv),
            stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
            env={**os.environ, **(env or {})},
            cwd=ROOT,
        )
        return cls(proc)

    async def _read(self) -> None:
        assert self.proc.stdout is not None
        async for line in self.proc.stdout:
            text = line.decode(errors="replace").strip()
            if text.startswith("{"):
                await self.events.put(json.loads(text))

    async def ask(self, command: str, timeout: float = 30.0) -> dict[str, Any]:
        """Send ``command``; the next JSON line whose ``event`` is the command's name."""
        self.tell(command)
        return await self.expect(command.split()[0], timeout)

    def tell(self, command: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(command.encode() + b"\n")

    async def expect(self, event: str, timeout: float = 30.0) -> dict[str, Any]:
        async with asyncio.timeout(timeout):
            while True:
                item = await self.events.get()
                if item.get("event") == event:
                    return item

    async def finish(self, timeout: float = 20.0) -> int:
        """Ask it to quit (closing stdin), then wait; killed when it does not."""
        if self.proc.stdin is not None and not self.proc.stdin.is_closing():
            self.proc.stdin.close()
        try:
            async with asyncio.timeout(timeout):
                code = await self.proc.wait()
        except TimeoutError:
            self.proc.kill()
            code = await self.proc.wait()
        await asyncio.wait({self._reader}, timeout=5)
        return code


def emit(result: dict[str, Any], out: str | None) -> None:
    """A section's result: to the ``--out`` file, or as the last line of stdout."""
    text = json.dumps(result, indent=1, default=str)
    if out:
        Path(out).write_text(text, encoding="utf-8")
    else:
        print(text)
