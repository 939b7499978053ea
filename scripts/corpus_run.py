"""A season of recorded tours, seeded: what `frog-bt report` is tested and measured on.

Each tour is a whole run of the real executive against the built-in simulator on sim
time (fast content, 400x), recorded to one MCAP file named by its local start time,
``YYYYMMDD-HHMMSS-tourNNNN.mcap``. From ``--seed``, per day (from 2026-06-01):
``--tours-per-day`` tours of one robot, one after another: the day's seven hours
(09:00-12:30, 14:30-18:00, where POI1 and POI2 play their afternoon variants) cut in
equal slots, each tour at a random moment of its slot early enough to end inside it
(a robot's tours cannot overlap; at most ``MOST_PER_DAY`` fit), each with one kind of
visitor, drawn with these weights:

==============  ======  =====================================================
kind            weight  what happens
==============  ======  =====================================================
``engaged``     0.40    accepts, faces the robot: parts a and b at POI1, POI2
``bored``       0.20    accepts, looks away: part a only (the engagement gate)
``declines``    0.15    the first visitor says no; a second one takes the tour
``wander_off``  0.10    follows to POI1, wanders off; the robot finds another
``nav_failure`` 0.10    the drive to POI2 fails once and is retried
``fault``       0.05    a motor driver error 5 minutes in: the tour is aborted
==============  ======  =====================================================

Then the season's help events, ``--help-each N`` tours of each kind below (default 4;
none from :func:`make` unless asked), put in place of tours drawn above by a second
generator of the same seed (so the tours drawn above do not change), each with the
default scenario's engaged visitor:

===============  ===========================================================================
help kind        what happens
===============  ===========================================================================
``dock_help``    the dock at the end fails 3 times: the robot holds and asks; a person puts it
                 on its charger and answers ``done_by_hand`` (``HELP_AFTER_S`` later)
``home``         the operator sends the robot home during POI3's content: aborted
``skip``         the operator skips POI3 during its content
``ack_alert``    the battery drops to 24 % at POI1 (the alert is below 25 %, the abort below
                 20 %); a person acknowledges ``battery_low`` ``ACK_AFTER_S`` after its raise
``restart``      the executive stops during POI3's content; a new one resumes the tour from
                 its checkpoint: two files, the second ``...-resumed.mcap``
===============  ===========================================================================

Operator commands go through the executive's staff (``by``: console), as the console
sends them.

``corpus.json`` beside the files lists every tour as seeded (file, day, local start,
kind), the seed, the weights and the help events, and per tour (``runs``) what the
corpus heard as it recorded: each file's first and last message (``spans``) and when a
person was needed (``needed``: each answer the executive accepted, each ERROR alert
from its raise to its clearing), so that a test can hold the report's figures against
them (scripts/check_report.py).

    scripts/corpus --out season/ --days 10 --tours-per-day 20 --help-each 4 --jobs 2
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, replace
from datetime import datetime, timedelta
from pathlib import Path
from typing import Any

KINDS: dict[str, float] = {
    "engaged": 0.40,
    "bored": 0.20,
    "declines": 0.15,
    "wander_off": 0.10,
    "nav_failure": 0.10,
    "fault": 0.05,
}
SCENARIO = {
    "engaged": "default",
    "bored": "bored",
    "declines": "declines",
    "wander_off": "wander_off",
    "nav_failure": "nav_failure",
    "fault": "fault",
}
HELP_KINDS = ("dock_help", "home", "skip", "ack_alert", "restart")
HELP_AFTER_S = 60.0  # simulated seconds from the help request to the person's done_by_hand
ACK_AFTER_S = 90.0  # simulated seconds from the battery_low alert's raise to its acknowledgement
LOW_BATTERY = 24.0  # percent: below the alert (25), above the abort (20)
FAST: dict[str, Any] = {"speed": 400.0, "content": {"default": 10, "introduction": 8}}
FIRST_DAY = "2026-06-01"
MORNING_MIN = 9 * 60  # the morning's tours from 09:00 (local minutes) ...
AFTERNOON_MIN = 14 * 60 + 30  # ... the afternoon's from 14:30
HALF_DAY_MIN = 3.5 * 60  # each for 3.5 hours
LONGEST_TOUR_MIN = 18.0  # a seeded tour's longest run (a wanderer's: 17 simulated minutes)
MOST_PER_DAY = int(2 * HALF_DAY_MIN // LONGEST_TOUR_MIN)
TZ = "+02:00"  # the site's summer time (Europe/Madrid)


@dataclass(frozen=True)
class Seeded:
    number: int  # tour number, from 1
    day: str  # YYYY-MM-DD
    start: str  # local start time, ISO 8601 with offset
    kind: str
    seed: int  # the simulator's seed for this tour
    file: str = ""  # relative to the corpus directory


def plan(
    days: int,
    per_day: int,
    seed: int,
    help_each: int = 0,
    weights: dict[str, float] | None = None,
) -> list[Seeded]:
    """The tours of a season, from ``seed``: in start order, numbered from 1; then
    ``help_each`` tours of each help kind in place of tours drawn at random (a second
    generator, so that the others are those ``help_each=0`` draws)."""
    weights = weights or KINDS
    if per_day > MOST_PER_DAY:
        raise ValueError(
            f"{per_day} tours a day: at most {MOST_PER_DAY} fit one robot's 7 hours one "
            "after another"
        )
    rng = random.Random(seed)
    out: list[Seeded] = []
    first = datetime.fromisoformat(f"{FIRST_DAY}T00:00:00{TZ}")
    slot = 2 * HALF_DAY_MIN / per_day
    number = 0
    for d in range(days):
        day = first + timedelta(days=d)
        starts = []
        for i in range(per_day):
            # one robot's day: its tours one after another, each at a random moment of
            # its slot early enough to end inside it (a robot's tours cannot overlap)
            minute = i * slot + rng.uniform(0.0, max(0.0, slot - LONGEST_TOUR_MIN))
            if minute >= HALF_DAY_MIN:
                minute += AFTERNOON_MIN - MORNING_MIN - HALF_DAY_MIN
            starts.append(day + timedelta(minutes=MORNING_MIN + minute))
        for start in starts:
            number += 1
            kind = rng.choices(list(weights), weights=list(weights.values()))[0]
            start = start.replace(microsecond=0)
            name = f"{start:%Y%m%d-%H%M%S}-tour{number:04d}.mcap"
            out.append(
                Seeded(
                    number, f"{day:%Y-%m-%d}", start.isoformat(), kind, rng.randrange(1 << 30), name
                )
            )
    if help_each:
        chosen = random.Random(f"help:{seed}").sample(range(len(out)), len(HELP_KINDS) * help_each)
        for i, number in enumerate(chosen):
            kind = HELP_KINDS[i % len(HELP_KINDS)]
            out[number] = replace(out[number], kind=kind)
    return out


def _scenario(tour: Seeded, fast: dict[str, Any]) -> Any:
    from frog_bt.sim import scenario_from

    data: dict[str, Any] = {**fast, "start_time": tour.start, "seed": tour.seed}
    if tour.kind == "dock_help":
        data["docking"] = {**data.get("docking", {}), "dock_failures": 3}
    return scenario_from(SCENARIO.get(tour.kind, "default"), data)


def _start_poi(poi: str) -> Any:
    return lambda r: (
        r.direction == "in" and r.channel == "start_poi" and r.payload.get("poi") == poi
    )


async def _until(executive: Any, ok: Any, limit: float = 600.0) -> None:
    """Wait on the executive's (simulated) clock until ``ok()``, one second at a time."""
    await executive.clock.wait_ready()
    end = executive.clock.now() + limit
    while not ok():
        if executive.clock.now() > end:
            raise TimeoutError("the rehearsal did not get there in time")
        await executive.clock.sleep(1.0)


async def _help(tour: Seeded, r: Any, acted: list[float]) -> None:
    """What the person does in a help tour (while the executive runs it); the executive
    clock's time of each answer it accepted goes in ``acted``."""
    from frog_bt.engine.operator import Command
    from frog_bt.model import keys
    from frog_bt.model.events import AlertChanged
    from frog_bt.model.outcomes import DockingState
    from frog_bt.runtime.observer import listen

    exe, sim = r.executive, r.sim
    if tour.kind == "dock_help":
        await _until(exe, lambda: "docking_failed" in exe.staff.book.active, 1800)
        await exe.clock.sleep(HELP_AFTER_S)
        docking = sim.world.docking  # a person puts the robot on its charger
        docking.state, docking.docked = "docked", True

        # as a person would: answer once the console shows the robot docked
        def docked() -> bool:
            reading = exe.core.board.get(keys.DOCKING)
            return reading is not None and reading.value == DockingState.DOCKED

        await _until(exe, docked, 30)
        answer = await exe.staff.submit(Command.DONE_BY_HAND, by="console")
        assert answer.ok, answer.text
        acted.append(exe.clock.now())
        return
    if tour.kind in ("home", "skip"):
        await sim.wait_for(_start_poi("POI3"), 60)
        command = Command.HOME if tour.kind == "home" else Command.SKIP
        answer = await exe.staff.submit(command, by="console")
        assert answer.ok, answer.text
        acted.append(exe.clock.now())
    elif tour.kind == "ack_alert":
        raised: list[float] = []
        listen(
            exe,
            lambda e: (
                raised.append(e.t)
                if e.alert.kind == "battery_low" and e.alert.state == "raised"
                else None
            ),
            AlertChanged,
        )
        await sim.wait_for(_start_poi("POI1"), 60)
        sim.world.battery.percentage = LOW_BATTERY
        await _until(exe, lambda: bool(raised), 60)
        await exe.clock.sleep_until(raised[0] + ACK_AFTER_S)
        answer = await exe.staff.submit(Command.ACK_ALERT, "battery_low", by="console")
        assert answer.ok, answer.text
        acted.append(exe.clock.now())


def record(tour: Seeded, directory: str, fast: dict[str, Any] | None = None) -> dict[str, Any]:
    """Run and record one tour (in a worker process); what happened, in brief."""
    import tempfile

    from frog_bt.config import load_site
    from frog_bt.live.recording import Recorder
    from frog_bt.model.events import AlertChanged, Ticked
    from frog_bt.rehearsal import Rehearsal
    from frog_bt.runtime.observer import attach_all, listen

    path = Path(directory) / tour.file
    path.parent.mkdir(parents=True, exist_ok=True)
    scenario = _scenario(tour, FAST if fast is None else fast)
    paths = [path]
    acted: list[float] = []  # when a person's answer was accepted (executive clock)
    alerts: list[dict[str, Any]] = []  # the alert changes the executives made, as heard

    def hear(exe: Any) -> None:
        listen(
            exe,
            lambda e: alerts.append(
                {"t": e.t, "id": e.alert.id, "state": e.alert.state, "severity": e.alert.severity}
            ),
            AlertChanged,
        )

    async def run() -> tuple[int, str]:
        site = load_site()
        recorder = Recorder(path)
        try:
            # a --once executive exits when the robot asks for help: this one waits for
            # the person's answer and stops at the tick the tour ends
            once = tour.kind != "dock_help"

            def prepare(exe: Any) -> None:
                attach_all(exe, [recorder])
                hear(exe)
                if not once:
                    listen(
                        exe,
                        lambda _e: exe.outcome.tours >= 1 and exe.stop("tour ended docked", 0),
                        Ticked,
                    )

            async with Rehearsal(scenario, site=site, prepare=prepare, once=once) as r:
                if tour.kind in HELP_KINDS:
                    await _help(tour, r, acted)
                outcome = await r.finish(120.0)
        finally:
            recorder.close()
        return outcome.code, outcome.reason

    async def resumed() -> tuple[int, str]:
        """The executive stops during POI3's content; a new one resumes from the checkpoint."""
        site = load_site()
        with tempfile.TemporaryDirectory() as tmp:
            checkpoint = Path(tmp) / "checkpoint.json"
            first = Recorder(path)
            run = Rehearsal(
                scenario,
                site=site,
                prepare=lambda exe: (attach_all(exe, [first]), hear(exe)),
                checkpoint=checkpoint,
                once=False,
            )
            try:
                async with run:
                    sim, listen = run.sim, run.listen
                    await sim.wait_for(_start_poi("POI3"), 60)
                    run.own_sim = False  # the simulator (the robot, the visitor) goes on
            finally:
                first.close()
            second_path = path.with_name(path.stem + "-resumed.mcap")
            paths.append(second_path)
            second = Recorder(second_path)
            again = Rehearsal(
                None,
                sim=sim,
                listen=listen,
                site=site,
                prepare=lambda exe: (attach_all(exe, [second]), hear(exe)),
                checkpoint=checkpoint,
            )
            try:
                async with again:
                    outcome = await again.finish(120.0)
            finally:
                second.close()
                await sim.stop()
        return outcome.code, outcome.reason

    t0 = time.monotonic()
    code, reason = asyncio.run(resumed() if tour.kind == "restart" else run())
    return {
        "file": tour.file,
        "files": [str(p.relative_to(directory)) for p in paths],
        "code": code,
        "reason": reason,
        "wall_s": round(time.monotonic() - t0, 2),
        "bytes": sum(p.stat().st_size for p in paths),
        "spans": [_span(p) for p in paths],
        "needed": _needed(acted, alerts),
    }


def _span(path: Path) -> list[float]:
    """The file's first and last message times (seconds), from its MCAP summary."""
    from mcap.reader import make_reader

    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None, path
    stats = summary.statistics
    return [stats.message_start_time / 1e9, stats.message_end_time / 1e9]


def _needed(acted: list[float], alerts: list[dict[str, Any]]) -> list[list[float]]:
    """When a person was needed, as heard while the tour ran: each accepted answer (a
    moment), and each ERROR alert from its raise to its clearing (to its acknowledgement
    when it was never cleared, to its raise when neither)."""
    out = [[t, t] for t in acted]
    open_: dict[str, list[float]] = {}  # id -> [raised, acknowledged or raised]
    for change in alerts:
        if change["severity"] != "ERROR":
            continue
        span = open_.get(change["id"])
        if change["state"] == "raised" and span is None:
            open_[change["id"]] = [change["t"], change["t"]]
        elif change["state"] == "acknowledged" and span is not None and span[1] == span[0]:
            span[1] = change["t"]
        elif change["state"] == "cleared" and span is not None:
            out.append([span[0], change["t"]])
            del open_[change["id"]]
    out += list(open_.values())
    return sorted(out)


def make(
    out: Path,
    days: int,
    per_day: int,
    seed: int,
    jobs: int = 1,
    progress: bool = False,
    *,
    help_each: int = 0,
    weights: dict[str, float] | None = None,
    fast: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Record the season into ``out`` and write ``out/corpus.json``; the manifest.

    ``help_each``: tours of each help kind (HELP_KINDS); ``weights``: the visitors'
    kinds (default KINDS); ``fast``: the simulator's speed and timings (default FAST)."""
    import multiprocessing

    out.mkdir(parents=True, exist_ok=True)
    tours = plan(days, per_day, seed, help_each, weights)
    context = multiprocessing.get_context("fork")
    t0 = time.monotonic()
    results = []
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        futures = [pool.submit(record, t, str(out), fast) for t in tours]
        for done, future in enumerate(futures, 1):
            results.append(future.result())
            if progress:
                print(f"\rcorpus: {done}/{len(tours)} tours", end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    manifest = {
        "seed": seed,
        "days": days,
        "tours_per_day": per_day,
        "weights": weights or KINDS,
        "help": {
            "each": help_each,
            "kinds": list(HELP_KINDS) if help_each else [],
            "help_after_s": HELP_AFTER_S,
            "ack_after_s": ACK_AFTER_S,
            "low_battery": LOW_BATTERY,
        },
        "tours": [asdict(t) for t in tours],
        "runs": results,
        "wall_s": round(time.monotonic() - t0, 1),
    }
    (out / "corpus.json").write_text(json.dumps(manifest, indent=1) + "\n")
    return manifest


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True, help="the corpus directory")
    p.add_argument("--days", type=int, default=10)
    p.add_argument("--tours-per-day", type=int, default=20)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--help-each", type=int, default=4, help="tours of each help kind (0: none)")
    p.add_argument("--jobs", type=int, default=2, help="tours recorded at once (processes)")
    a = p.parse_args()
    for option, value, least in (
        ("--days", a.days, 1),
        ("--tours-per-day", a.tours_per_day, 1),
        ("--jobs", a.jobs, 1),
        ("--help-each", a.help_each, 0),
    ):
        if value < least:
            p.error(f"{option} {value}: expected {least} or more")
    if a.help_each * len(HELP_KINDS) > a.days * a.tours_per_day:
        p.error(
            f"--help-each {a.help_each}: {a.help_each * len(HELP_KINDS)} help tours "
            f"({len(HELP_KINDS)} kinds) do not fit a season of {a.days * a.tours_per_day} tours"
        )
    if a.tours_per_day > MOST_PER_DAY:
        p.error(
            f"--tours-per-day: at most {MOST_PER_DAY} tours fit one robot's day one after another"
        )
    manifest = make(
        a.out, a.days, a.tours_per_day, a.seed, a.jobs, progress=True, help_each=a.help_each
    )
    kinds: dict[str, int] = {}
    for t in manifest["tours"]:
        kinds[t["kind"]] = kinds.get(t["kind"], 0) + 1
    failed = [r for r in manifest["runs"] if r["code"] != 0]
    size = sum(r["bytes"] for r in manifest["runs"])
    print(
        f"corpus: {len(manifest['tours'])} tours in {a.out} ({size / 1e6:.0f} MB, "
        f"{manifest['wall_s']:.0f} s): "
        + ", ".join(f"{n} {k}" for k, n in kinds.items())
        + f"; {len(failed)} ended non-zero"
    )


if __name__ == "__main__":
    main()
