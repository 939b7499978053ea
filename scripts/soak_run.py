"""A day on the robot, fast: `frog-bt run` for N tours back to back against the
simulator, with faults injected on a seeded schedule.

The executive is the installed command (``frog-bt run --sim-time --record DIR
--checkpoint FILE``) in a process of its own; the simulator runs here, on a
fast-tour scenario with 15 % datagram loss each way. Faults, drawn per tour
from ``--seed`` and injected at a random simulated time into that tour:

* ``rosbridge``: the rosbridge server stops (every client dropped) and listens
  again 5 s (simulated) later;
* ``frontend``: the front end restarts (its numbering starts again at 1);
* ``stale``: person detections, tracks and the robot's pose stop for 8 s
  (simulated): the perception goes stale;
* ``battery``: once, at the middle tour, the battery falls to 15 %;
* ``kill``: every ~10 tours, ``kill -9`` of the executive; it is started
  again at once, on the same checkpoint and recording directory.

Faults go by simulated time: each waits on the simulator's clock for its moment in
its tour, and one whose tour ended first goes into the next tour, 5 s in. The wall
clock only catches a hang (``wall_timeout``), so a loaded machine gives the same day.

The report (printed, and written as JSON with ``--out``) accounts for every
tour from what the front end received: started, completed, aborted (with the
reasons), unaccounted (started, then never ended nor aborted); visitors
stranded (a tour that started and whose visitor was never told it ended);
front-end commands lost (sent, never acked; from the recordings); the
executive's RSS at each tour end; the faults injected; wall time.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import random
import signal
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import FROG_BT, LOOPBACK, emit, free_port, memory_kb

# Tours back to back: a fast robot, short content, a visitor who comes back, a lossy
# front-end link, a battery that charges fast at the dock.
SOAK_SCENARIO: dict[str, Any] = {
    "navigation": {"speed": 3.0, "approach_time": 1.0},
    "docking": {"undock_time": 2.0, "dock_time": 3.0},
    "content": {"default": 4, "introduction": 3},
    "battery": {"start": 95, "charge_per_hour": 300},
    "frontend": {"idle_at": 1.0, "idle_after_tour": 1.0, "answer_delay": 1.0, "loss": 0.15},
}
DEFAULT_SCRIPTS = Path(__file__).resolve().parents[2] / "shared" / "real-rosbridge"
PERCEPTION = ("persons", "people", "pose")  # wire roles that go stale together
KINDS = ("rosbridge", "frontend", "stale", "battery", "kill")
OUTAGE = 5.0  # simulated seconds the simulator's rosbridge server is away
CARRIED_DELAY = 5.0  # a fault whose tour ended first: this far into the next tour


@dataclass
class Fault:
    tour: int  # injected during this tour (1-based)
    kind: str
    delay: float  # simulated seconds after the tour started
    done_at: float | None = None  # simulated time it was injected


def schedule(
    tours: int,
    seed: int,
    *,
    rosbridge: float = 0.25,
    frontend: float = 0.15,
    stale: float = 0.2,
    kill_every: int = 10,
) -> list[Fault]:
    """The faults of a soak of ``tours`` tours, from ``seed``: per tour, each kind with
    its probability; the battery once, in the middle tour; a kill every ``kill_every``
    tours (at a tour drawn within each block)."""
    rng = random.Random(seed)
    out: list[Fault] = []
    for tour in range(1, tours + 1):
        for kind, p in (("rosbridge", rosbridge), ("frontend", frontend), ("stale", stale)):
            if rng.random() < p:
                out.append(Fault(tour, kind, rng.uniform(5.0, 60.0)))
    out.append(Fault(max(1, (tours + 1) // 2), "battery", rng.uniform(10.0, 40.0)))
    for block in range(0, tours, kill_every):
        last = min(tours, block + kill_every)
        if last - block >= max(1, kill_every // 2):  # a short last block: no kill
            out.append(Fault(rng.randint(block + 1, last), "kill", rng.uniform(5.0, 60.0)))
    return sorted(out, key=lambda f: (f.tour, f.delay))


@dataclass
class Report:
    tours_wanted: int
    started: int = 0
    completed: int = 0
    aborted: int = 0
    abort_reasons: dict[str, int] = field(default_factory=dict)
    resumed: int = 0  # a started tour carried on by a restarted executive
    unaccounted: int = 0
    stranded: int = 0
    commands_sent: int = 0
    commands_lost: int = 0
    restarts: int = 0
    faults: dict[str, int] = field(default_factory=dict)
    rss_kb: list[int] = field(default_factory=list)
    events: list[str] = field(default_factory=list)  # tour states, in order
    resends_taken: int = 0  # tour-state resends the simulated front end took anew
    rss_growth_pct: float | None = None  # from the 10th tour's end (or the first) to the last
    wall_s: float = 0.0
    sim_s: float = 0.0
    timed_out: bool = False
    # with --via-rosbridge: the real server between the executive and the robot
    server: str | None = None
    server_restarts: int = 0
    server_restart_wall_s: list[float] = field(default_factory=list)
    robot_connections: int = 0  # times the simulated robot connected to the server
    restarts_answered: int = 0  # restarts after which the robot got a command again
    content_started_twice: int = 0  # a (stop, part) started again in one tour, new seq

    def lines(self) -> list[str]:
        reasons = ", ".join(f"{n} {r}" for r, n in self.abort_reasons.items()) or "none"
        growth = "n/a" if self.rss_growth_pct is None else f"{self.rss_growth_pct:+.1f} %"
        return [
            f"soak: {self.started} tours started, {self.completed} completed, {self.aborted} "
            f"aborted ({reasons}), {self.resumed} resumed after a kill",
            f"  unaccounted {self.unaccounted}, visitors stranded {self.stranded}, front-end "
            f"commands lost {self.commands_lost} of {self.commands_sent}",
            "  faults: "
            + ", ".join(f"{k} {n}" for k, n in self.faults.items())
            + f"; executive restarts {self.restarts}",
            f"  RSS {self.rss_kb[0] if self.rss_kb else 0} -> "
            f"{self.rss_kb[-1] if self.rss_kb else 0} kB ({growth}); "
            f"{self.sim_s / 3600:.1f} h simulated in {self.wall_s:.0f} s wall"
            + ("; TIMED OUT" if self.timed_out else ""),
        ] + (
            [
                f"  via {self.server}: {self.server_restarts} server restarts, the robot "
                f"connected {self.robot_connections} times, {self.restarts_answered} restarts "
                f"followed by commands reaching the robot; content parts started twice "
                f"{self.content_started_twice}",
            ]
            if self.server
            else []
        )


class Executive:
    """``frog-bt run`` in a child process; started again after a kill."""

    def __init__(self, argv: list[str], logs: Path, env: dict[str, str] | None = None) -> None:
        self.argv = argv
        self.logs = logs
        self.env = {**os.environ, **(env or {})}
        self.proc: asyncio.subprocess.Process | None = None
        self.starts = 0

    async def start(self) -> None:
        self.starts += 1
        log = open(self.logs / f"executive-{self.starts}.log", "wb")  # noqa: SIM115
        self.proc = await asyncio.create_subprocess_exec(
            *self.argv, stdin=asyncio.subprocess.DEVNULL, stdout=log, stderr=log, env=self.env
        )
        log.close()

    async def kill(self) -> None:
        assert self.proc is not None
        os.kill(self.proc.pid, signal.SIGKILL)
        await self.proc.wait()

    async def stop(self, timeout: float = 10.0) -> None:
        if self.proc is None or self.proc.returncode is not None:
            return
        self.proc.send_signal(signal.SIGTERM)
        try:
            await asyncio.wait_for(self.proc.wait(), timeout)
        except TimeoutError:
            self.proc.kill()
            await self.proc.wait()

    def rss_kb(self) -> int:
        return memory_kb(self.proc.pid).get("rss_kb", 0) if self.proc else 0


class RealServer:
    """A real rosbridge_suite on loopback, restarted with its own scripts (``stop.sh PORT``,
    ``start.sh PORT`` of ../shared/real-rosbridge): the ROS master goes with it."""

    def __init__(self, scripts: Path, port: int) -> None:
        self.scripts = scripts
        self.port = port
        self.restarts = 0
        self.restart_wall: list[float] = []  # seconds each stop+start took

    async def _sh(self, name: str) -> None:
        proc = await asyncio.create_subprocess_exec(
            "bash",
            str(self.scripts / name),
            str(self.port),
            stdout=asyncio.subprocess.DEVNULL,
            stderr=asyncio.subprocess.PIPE,
        )
        _, err = await proc.communicate()
        if proc.returncode != 0:
            raise RuntimeError(
                f"{name} {self.port}: exit {proc.returncode}: "
                f"{err.decode(errors='replace').strip()[-300:]}"
            )

    async def restart(self) -> None:
        t0 = time.monotonic()
        await self._sh("stop.sh")
        await asyncio.sleep(2.0)  # the server is away for 2 s of wall time, as in the sim
        await self._sh("start.sh")
        self.restarts += 1
        self.restart_wall.append(time.monotonic() - t0)


async def soak(
    tours: int,
    seed: int,
    workdir: Path,
    *,
    speed: float = 200.0,
    faults: list[Fault] | None = None,
    wall_timeout: float = 3600.0,
    via: str | None = None,
    server: RealServer | None = None,
    secret: str | None = None,
) -> Report:
    """``via``: the rosbridge server (a real one) between the executive and the simulated
    robot; ``server`` restarts it for each ``rosbridge`` fault; ``secret``: its rosauth."""
    from frog_bt.config import load_site
    from frog_bt.sim import Simulator, scenario_from
    from frog_bt.sim.traffic import Record

    site = load_site()
    plan = faults if faults is not None else schedule(tours, seed)
    listen = (LOOPBACK, free_port())
    sim = Simulator(
        scenario_from("default", {**SOAK_SCENARIO, "speed": speed, "seed": seed}),
        host=LOOPBACK,
        rosbridge_port=0,
        frontend_port=0,
        executive=listen,
        via=via,
        secret=secret,
    )
    await sim.start()
    record_dir = workdir / "recordings"
    argv = [
        str(FROG_BT),
        "run",
        "--sim-time",
        "--quiet",
        "--record",
        str(record_dir),
        "--checkpoint",
        str(workdir / "checkpoint.json"),
        "--rosbridge",
        via or f"ws://{LOOPBACK}:{sim.rosbridge_port}",
        "--frontend",
        f"{LOOPBACK}:{sim.frontend_port}",
        "--listen",
        f"{LOOPBACK}:{listen[1]}",
    ]
    executive = Executive(argv, workdir, {"FROG_ROSBRIDGE_SECRET": secret} if secret else {})
    report = Report(tours)
    state = {"tour": 0, "open": False, "started_at": 0.0}
    ended = asyncio.Event()
    changed = asyncio.Event()
    killed_during_open = [False]

    started_parts: dict[tuple[str, str], object] = {}  # this tour's content parts -> seq
    since_restart = [True]  # a command reached the robot since the last server restart
    tour_said: set[tuple[int, object]] = set()  # (executive start, seq) of each tour state
    acked: list[tuple[float, object] | None] = [None]  # the front end's latest ack: (t, seq)

    def on_record(record: Record) -> None:
        if record.side == "frontend" and record.direction == "out" and record.channel == "ack":
            # the front end acks a datagram just before it logs what it holds: its seq
            acked[0] = (record.t, record.payload.get("seq"))
            return
        if record.side == "ros" and record.direction == "in":
            if not since_restart[0]:
                since_restart[0] = True
                report.restarts_answered += 1
            return
        if record.side == "frontend" and record.direction == "in" and record.channel == "start_poi":
            part = (str(record.payload.get("poi")), str(record.payload.get("part")))
            seq = record.payload.get("seq")
            if part in started_parts and started_parts[part] != seq:
                report.content_started_twice += 1
            started_parts[part] = seq
            return
        if record.side != "frontend" or record.direction != "in" or record.channel != "tour":
            return
        seq = acked[0][1] if acked[0] is not None and acked[0][0] == record.t else None
        said = (executive.starts, seq)
        if seq is not None and said in tour_said:
            # A resend the simulated front end took anew (its dedup window is 10 s of
            # simulated time; a lost ack and a slow executive resend later than that):
            # one command of the executive's, one seq, counted once.
            report.resends_taken += 1
            return
        tour_said.add(said)
        what = record.payload.get("state")
        report.events.append(f"{record.t:.1f} tour {what}")
        if report.completed + report.aborted >= tours:
            return  # the soak is over: a tour the executive starts before it is stopped is
            # not one of the soak's (it would count as stranded, a race at the end)
        if what == "started":
            if state["open"]:
                if killed_during_open[0]:
                    report.resumed += 1  # a restarted executive says so again
                    killed_during_open[0] = False
                    return
                report.events.append("a second tour started without an end or a kill")
                report.unaccounted += 1  # the first one was never ended
                return
            else:
                state["tour"] += 1
                started_parts.clear()
            state["open"], state["started_at"] = True, record.t
            report.started += 1
            changed.set()
        elif what in ("ended", "aborted") and state["open"]:
            state["open"] = False
            if killed_during_open[0]:
                report.resumed += 1  # carried on to its end by the restarted executive
            killed_during_open[0] = False
            if what == "ended":
                report.completed += 1
            else:
                report.aborted += 1
                reason = str(record.payload.get("reason") or "?")
                report.abort_reasons[reason] = report.abort_reasons.get(reason, 0) + 1
            report.rss_kb.append(executive.rss_kb())
            changed.set()
            if report.completed + report.aborted >= tours:
                ended.set()

    sim.log.add_listener(on_record)

    def under_way(tour: int) -> bool:
        return bool(state["open"]) and state["tour"] == tour

    async def tour_event() -> None:
        changed.clear()
        await changed.wait()

    async def at_or_closed(at: float, tour: int) -> bool:
        """Wait until simulated time ``at`` in ``tour``; False when the tour ends first."""
        sleeper = asyncio.ensure_future(sim.clock.sleep_until(at))
        try:
            while not sleeper.done() and under_way(tour):
                event = asyncio.ensure_future(tour_event())
                await asyncio.wait({sleeper, event}, return_when=asyncio.FIRST_COMPLETED)
                event.cancel()
        finally:
            sleeper.cancel()
        return under_way(tour)

    async def drive_faults() -> None:
        """Each fault at its simulated time in its tour, in order; a fault whose tour ends
        first goes into the next tour (a fast or loaded day never skips one)."""
        for fault in plan:
            while True:
                while not (state["open"] and state["tour"] >= fault.tour):
                    await tour_event()
                tour, started = int(state["tour"]), float(state["started_at"])
                delay = fault.delay if tour == fault.tour else min(fault.delay, CARRIED_DELAY)
                if await at_or_closed(started + delay, tour):
                    break
                report.events.append(f"{sim.clock.now():.1f} {fault.kind} carried past tour {tour}")
            async with restarting:  # a kill starts it again: not the main loop too
                await inject(fault, sim, site, executive, killed_during_open, server)
            if fault.kind == "rosbridge" and server is not None:
                since_restart[0] = False
            fault.done_at = sim.clock.now()
            report.events.append(f"{fault.done_at:.1f} {fault.kind} in tour {state['tour']}")
            report.faults[fault.kind] = report.faults.get(fault.kind, 0) + 1

    restarting = asyncio.Lock()
    wall0, sim0 = time.monotonic(), sim.clock.now()
    await executive.start()
    faults_task = asyncio.create_task(drive_faults(), name="soak faults")
    try:
        deadline = wall0 + wall_timeout  # only catches a hang: faults go by simulated time
        while not ended.is_set():
            if time.monotonic() > deadline:
                report.timed_out = True
                break
            if faults_task.done() and faults_task.exception() is not None:
                raise faults_task.exception()  # type: ignore[misc]
            async with restarting:
                if executive.proc is not None and executive.proc.returncode is not None:
                    await executive.start()  # it stopped on its own (it gave up): go on
            with contextlib.suppress(TimeoutError):  # the end, or look again
                await asyncio.wait_for(ended.wait(), 0.5)
    finally:
        faults_task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await faults_task
        await executive.stop()
        await sim.stop()
    report.restarts = executive.starts - 1
    if server is not None:
        report.server = via
        report.server_restarts = server.restarts
        report.server_restart_wall_s = [round(w, 1) for w in server.restart_wall]
        report.robot_connections = sim._rosbridge.connections
    report.wall_s = time.monotonic() - wall0
    report.sim_s = sim.clock.now() - sim0
    if state["open"]:
        report.unaccounted += 1
    report.stranded = report.unaccounted
    report.commands_sent, report.commands_lost = lost_commands(record_dir)
    if len(report.rss_kb) >= 2:
        base = report.rss_kb[min(9, len(report.rss_kb) - 2)]
        report.rss_growth_pct = 100.0 * (report.rss_kb[-1] - base) / max(base, 1)
    return report


async def inject(
    fault: Fault,
    sim: Any,
    site: Any,
    executive: Executive,
    killed_during_open: list[bool],
    server: RealServer | None = None,
) -> None:
    if fault.kind == "rosbridge" and server is not None:
        await server.restart()
    elif fault.kind == "rosbridge":
        await sim.stop_rosbridge()
        await sim.clock.sleep(OUTAGE)  # the server is away for OUTAGE simulated seconds
        await sim.start_rosbridge()
    elif fault.kind == "frontend":
        sim.restart_frontend()
    elif fault.kind == "stale":
        for role in PERCEPTION:
            sim.drop(site.topic(role), 8.0)
    elif fault.kind == "battery":
        sim.world.battery.percentage = 15.0
    elif fault.kind == "kill":
        killed_during_open[0] = True
        await executive.kill()
        await executive.start()


def lost_commands(record_dir: Path) -> tuple[int, int]:
    """(front-end commands sent, never acked), from the recordings in order: a command's
    seq is taken once (resends are not new), an ack with its seq settles it; when the
    numbering starts again (a restarted executive), what is open is lost."""
    from frog_bt.live.rotation import numbered
    from frog_bt.model.channels import FRONTEND_IN, FRONTEND_OUT
    from frog_bt.recordings.mcapfile import RecordingError, open_recording

    sent = lost = 0
    open_seqs: set[int] = set()
    last_seq = 0
    for _, path in numbered(record_dir):
        try:
            recording = open_recording(path)
        except RecordingError:
            continue
        for topic, _ns, data in recording.messages():
            if topic not in (FRONTEND_IN, FRONTEND_OUT):
                continue
            try:
                obj = json.loads(data)
            except ValueError:
                continue
            seq = obj.get("seq") if isinstance(obj, dict) else None
            if not isinstance(seq, int):
                continue
            if topic == FRONTEND_OUT and obj.get("type") != "ack":
                if seq in open_seqs:
                    continue  # a resend
                if seq <= last_seq:  # numbering started again: a new executive
                    lost += len(open_seqs)
                    open_seqs.clear()
                last_seq = seq
                sent += 1
                open_seqs.add(seq)
            elif topic == FRONTEND_IN and obj.get("type") == "ack":
                open_seqs.discard(seq)
    return sent, lost + len(open_seqs)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tours", type=int, default=100)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--speed", type=float, default=200.0, help="sim-time speed factor")
    p.add_argument("--keep", type=Path, help="keep the recordings and logs in this directory")
    p.add_argument("--out", help="write the report as JSON here")
    p.add_argument(
        "--via-rosbridge",
        metavar="URL",
        help="a real rosbridge_suite server (ws://127.0.0.1:PORT) between the "
        "executive and the simulated robot (frog-bt sim --via); each "
        "rosbridge fault restarts it with --server-scripts' stop.sh/start.sh",
    )
    p.add_argument(
        "--server-scripts",
        type=Path,
        default=DEFAULT_SCRIPTS,
        metavar="DIR",
        help=f"the real server's start.sh and stop.sh (default {DEFAULT_SCRIPTS})",
    )
    p.add_argument(
        "--server-restarts",
        type=int,
        default=20,
        metavar="N",
        help="with --via-rosbridge: restart the server at least N times, in as "
        "many tours (default 20)",
    )
    p.add_argument(
        "--secret-file",
        type=Path,
        metavar="FILE",
        help="with --via-rosbridge: the server's rosauth secret (first line), for "
        "the executive and the robot (start.sh's FROG_RB_AUTH_SECRET_FILE)",
    )
    args = p.parse_args()
    server = secret = faults = None
    if args.via_rosbridge:
        port = int(args.via_rosbridge.rstrip("/").rsplit(":", 1)[1])
        server = RealServer(args.server_scripts, port)
        if args.secret_file:
            secret = args.secret_file.read_text().splitlines()[0].strip()
        faults = schedule(args.tours, args.seed, rosbridge=0.0)
        # a server restart in each of the first N tours (a tour may well hold two)
        rng = random.Random(args.seed)
        faults += [
            Fault(1 + i % args.tours, "rosbridge", rng.uniform(5.0, 40.0))
            for i in range(args.server_restarts)
        ]
        faults.sort(key=lambda f: (f.tour, f.delay))
    with tempfile.TemporaryDirectory(prefix="frog-soak-") as tmp:
        workdir = args.keep or Path(tmp)
        workdir.mkdir(parents=True, exist_ok=True)
        report = asyncio.run(
            soak(
                args.tours,
                args.seed,
                workdir,
                speed=args.speed,
                faults=faults,
                via=args.via_rosbridge,
                server=server,
                secret=secret,
            )
        )
    print("\n".join(report.lines()), file=sys.stderr)
    emit(asdict(report), args.out)


if __name__ == "__main__":
    main()
