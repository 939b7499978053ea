"""Tours of different kinds, each a whole run of the real executive against the simulator
(fast, sim time), recorded as `frog-bt run --record DIR` records them: rotating files,
one idle and one tour file per tour, in one directory (one robot), one tour a day.

:func:`record_day` runs them in worker processes and returns what the simulator
received of each tour (the other side's account, to hold the report's rows against).
"""

from __future__ import annotations

import asyncio
import math
import multiprocessing
from collections.abc import Awaitable, Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.live.rotation import RecordingDir
from frog_bt.model.events import FrontendIn, FrontendOut, RobotInput
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.observer import attach_all, listen
from frog_bt.sim import scenario_from
from frog_bt.sim.traffic import Record
from tests.recording.recorded_tour import FAST_TOURS

# Tours in about 0.6 s of wall time: a fast robot, short content, quick answers.
FAST = FAST_TOURS

# kind -> (scenario, overrides, local start); one day each, so that no two overlap
KINDS: dict[str, tuple[str, dict[str, Any], str]] = {
    "afternoon": ("afternoon", {}, "2026-06-02T15:00:00"),
    "bored": ("bored", {}, "2026-06-03T10:00:00"),
    "declines": ("declines", {}, "2026-06-04T10:00:00"),
    "declined_then_home": ("declines", {}, "2026-06-05T10:00:00"),
    "nav_failure": (
        "nav_failure",
        {
            "navigation": {
                "failures": [{"poi": "POI1", "times": 3, "result": "aborted", "after": 1.0}]
            }
        },
        "2026-06-06T11:00:00",
    ),
    "fault": (
        "fault",
        {
            "faults": [
                {"at": 60, "name": "motors", "level": 2, "message": "motor driver overheated"}
            ]
        },
        "2026-06-07T10:00:00",
    ),
    "operator_skips": ("default", {}, "2026-06-08T10:00:00"),
    "undock_failure": ("undock_failure", {}, "2026-06-09T10:00:00"),
    "wander_off": ("wander_off", {}, "2026-06-10T10:00:00"),
    "resumed": ("default", {}, "2026-06-11T10:00:00"),
    # a front end that never acks: every command sent 8 times, `tour started` again
    # into the tour file after the rotation
    "unacked": ("default", {"frontend": {"ack": False}}, "2026-06-12T10:00:00"),
}


@dataclass
class Seen:
    """What the simulator received from the executive during one tour."""

    kind: str
    code: int
    reason: str
    frontend: list[dict[str, Any]] = field(default_factory=list)  # commands, in order
    ros: list[tuple[str, Any]] = field(default_factory=list)  # (topic, msg), in order
    answers: list[str] = field(default_factory=list)  # user_positive / user_negative sent
    path_m: float = 0.0  # the robot's path, from the poses the simulator published
    # the executives' own clock (what a recording is stamped with): when each sent `tour`
    # (its state) and heard /docking/state say docked
    told: list[tuple[float, str]] = field(default_factory=list)
    heard_docked: list[float] = field(default_factory=list)

    def of(self, type_: str) -> list[dict[str, Any]]:
        return [m for m in self.frontend if m["type"] == type_]

    @property
    def duration(self) -> float:
        """From `tour started` to `tour ended` (docked by then), or to docked again after
        `tour aborted`, as the executives timed them: the simulator's clock runs ahead of
        theirs by the link's latency, many simulated seconds a wall millisecond at 400x."""
        (start, _), (end, state) = self.told[0], self.told[-1]
        if state == "aborted":
            end = next(t for t in self.heard_docked if t >= end)
        return end - start


def hear(exe: Any, seen: Seen) -> None:
    """Keep in ``seen`` what ``exe`` sent of the tour and heard of docking, when."""

    def out(e: FrontendOut) -> None:
        if e.message.type == "tour":
            seen.told.append((e.t, str(e.message.state)))

    def docking(e: RobotInput) -> None:
        if e.topic == "/docking/state" and str(e.value) == "docked":
            seen.heard_docked.append(e.t)

    listen(exe, out, FrontendOut)
    listen(exe, docking, RobotInput)


def _merge(a: dict[str, Any], b: dict[str, Any]) -> dict[str, Any]:
    out = dict(a)
    for k, v in b.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _is(channel: str, **fields: Any) -> Callable[[Record], bool]:
    return lambda r: (
        r.direction == "in"
        and r.channel == channel
        and all(r.payload.get(k) == v for k, v in fields.items())
    )


async def _home_after_a_no(r: Rehearsal) -> None:
    no = asyncio.Event()
    listen(
        r.executive, lambda e: no.set() if e.message.type == "user_negative" else None, FrontendIn
    )
    await asyncio.wait_for(no.wait(), 60)  # the executive has the visitor's no
    assert r.executive.core.command(Command.HOME).ok


async def _skip_content_then_drive(r: Rehearsal) -> None:
    await r.sim.wait_for(_is("start_poi", poi="POI3", part="a"), 60)
    assert r.executive.core.command(Command.SKIP).ok  # during POI3's content
    await r.sim.wait_for(
        lambda rec: (
            rec.channel == "/GotoWayPoint" and rec.payload["pose"]["position"]["x"] == 51.7105
        ),
        60,
    )
    assert r.executive.core.command(Command.SKIP).ok  # during the drive to POI4


ACTIONS: dict[str, Callable[[Rehearsal], Awaitable[None]]] = {
    "declined_then_home": _home_after_a_no,
    "operator_skips": _skip_content_then_drive,
}


def _seen(kind: str, code: int, reason: str, records: list[Record], seen: Seen) -> Seen:
    """The simulator's log, for one tour, into ``seen``. The simulated front end logs a
    command once, however often it was sent."""
    seen.code, seen.reason = code, reason
    pose: tuple[float, float] | None = None
    for rec in records:
        if rec.direction == "in" and rec.side == "frontend" and rec.channel != "ack":
            seen.frontend.append({"type": rec.channel, **rec.payload})
        elif rec.direction == "in" and rec.side == "ros":
            seen.ros.append((rec.channel, rec.payload))
        elif rec.direction == "out" and rec.channel in ("user_positive", "user_negative"):
            seen.answers.append(rec.channel)
        elif rec.direction == "out" and rec.channel == "/FROG_pose":
            p = rec.payload["pose"]["position"]
            if pose is not None:
                seen.path_m += math.hypot(p["x"] - pose[0], p["y"] - pose[1])
            pose = (p["x"], p["y"])
    return seen


async def _tour(directory: Path, kind: str) -> Seen:
    name, overrides, start = KINDS[kind]
    data = _merge(_merge(FAST, overrides), {"start_time": start + "+02:00"})
    site = load_site()
    seen = Seen(kind, 0, "")
    recordings = RecordingDir(directory, 10**12)
    run = Rehearsal(
        scenario_from(name, data),
        site=site,
        prepare=lambda exe: (attach_all(exe, [recordings]), hear(exe, seen)),
        memory=True,
    )
    try:
        async with run:
            action = ACTIONS.get(kind)
            if action is not None:
                await action(run)
            outcome = await run.finish(60)
    finally:
        recordings.close()
    return _seen(kind, outcome.code, outcome.reason, list(run.sim.log), seen)


RESTART_INTO_POI2_S = 2.0  # simulated seconds of POI2's part a (4 s) before the stop


async def _resumed(directory: Path, checkpoint: Path) -> Seen:
    """A tour whose executive stops during POI2's content (its files closed as SIGTERM
    closes them) and a new executive that resumes it from the checkpoint."""
    name, _, start = KINDS["resumed"]
    site = load_site()
    seen = Seen("resumed", 0, "")
    first = RecordingDir(directory, 10**12)
    run = Rehearsal(
        scenario_from(name, _merge(FAST, {"start_time": start + "+02:00"})),
        site=site,
        prepare=lambda exe: (attach_all(exe, [first]), hear(exe, seen)),
        checkpoint=checkpoint,
        once=False,
        memory=True,
    )
    try:
        async with run:
            sim, listen = run.sim, run.listen
            await sim.wait_for(_is("start_poi", poi="POI2", part="a"), 60)
            await run.executive.clock.sleep(RESTART_INTO_POI2_S)
            run.own_sim = False  # the simulator (the robot, the visitor) goes on
    finally:
        first.close()
    second = RecordingDir(directory, 10**12)
    again = Rehearsal(
        None,
        sim=sim,
        listen=listen,
        site=site,
        prepare=lambda exe: (attach_all(exe, [second]), hear(exe, seen)),
        checkpoint=checkpoint,
    )
    try:
        async with again:
            outcome = await again.finish(60)
    finally:
        second.close()
        await sim.stop()
    return _seen("resumed", outcome.code, outcome.reason, list(sim.log), seen)


def record(directory: str, kind: str) -> Seen:
    """One tour of ``kind`` recorded into ``directory`` (in a worker process)."""
    if kind == "resumed":
        return asyncio.run(_resumed(Path(directory), Path(directory).parent / "checkpoint"))
    return asyncio.run(_tour(Path(directory), kind))


def record_day(directory: Path, kinds: list[str], jobs: int = 2) -> dict[str, Seen]:
    """Every tour of ``kinds`` recorded into ``directory`` (one robot); kind -> Seen."""
    directory.mkdir(parents=True, exist_ok=True)
    context = multiprocessing.get_context("fork")
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        futures = {kind: pool.submit(record, str(directory / kind), kind) for kind in kinds}
        seen = {kind: f.result() for kind, f in futures.items()}
    # one robot's directory: every tour's files together, as one --record DIR holds them
    for kind in kinds:
        for path in (directory / kind).glob("*.mcap"):
            path.rename(directory / path.name)
        (directory / kind).rmdir()
    return seen
