"""A season of recorded tours, seeded: what `frog-bt report` is tested and measured on.

Each tour is a whole run of the real executive against the built-in simulator on sim
time (fast content, 400x), recorded to one MCAP file named by its local start time,
``YYYYMMDD-HHMMSS-tourNNNN.mcap``. From ``--seed``, per day (from 2026-06-01):
``--tours-per-day`` tours, each in the morning (09:00-12:30) or the afternoon
(14:30-18:00, where POI1 and POI2 play their afternoon variants), each with one kind
of visitor, drawn with these weights:

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

``corpus.json`` beside the files lists every tour as seeded (file, day, local start,
kind), the seed and the weights, so that a test can hold the report's figures
against them.

    scripts/corpus --out season/ --days 10 --tours-per-day 20 --jobs 2
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
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
FAST: dict[str, Any] = {"speed": 400.0, "content": {"default": 10, "introduction": 8}}
FIRST_DAY = "2026-06-01"
TZ = "+02:00"  # the site's summer time (Europe/Madrid)


@dataclass(frozen=True)
class Seeded:
    number: int  # tour number, from 1
    day: str  # YYYY-MM-DD
    start: str  # local start time, ISO 8601 with offset
    kind: str
    seed: int  # the simulator's seed for this tour
    file: str = ""  # relative to the corpus directory


def plan(days: int, per_day: int, seed: int) -> list[Seeded]:
    """The tours of a season, from ``seed``: in start order, numbered from 1."""
    rng = random.Random(seed)
    out: list[Seeded] = []
    first = datetime.fromisoformat(f"{FIRST_DAY}T00:00:00{TZ}")
    number = 0
    for d in range(days):
        day = first + timedelta(days=d)
        starts = sorted(
            day
            + timedelta(
                minutes=rng.choice(
                    (rng.uniform(9 * 60, 12.5 * 60), rng.uniform(14.5 * 60, 18 * 60))
                )
            )
            for _ in range(per_day)
        )
        for start in starts:
            number += 1
            kind = rng.choices(list(KINDS), weights=list(KINDS.values()))[0]
            start = start.replace(microsecond=0)
            name = f"{start:%Y%m%d-%H%M%S}-tour{number:04d}.mcap"
            out.append(
                Seeded(
                    number, f"{day:%Y-%m-%d}", start.isoformat(), kind, rng.randrange(1 << 30), name
                )
            )
    return out


def record(tour: Seeded, directory: str) -> dict[str, Any]:
    """Run and record one tour (in a worker process); what happened, in brief."""
    from frog_bt.config import load_site
    from frog_bt.live.recording import Recorder
    from frog_bt.rehearsal import Rehearsal
    from frog_bt.runtime.observer import attach_all
    from frog_bt.sim import scenario_from

    path = Path(directory) / tour.file
    scenario = scenario_from(
        SCENARIO[tour.kind], {**FAST, "start_time": tour.start, "seed": tour.seed}
    )

    async def run() -> tuple[int, str]:
        recorder = Recorder(path)
        try:
            async with Rehearsal(
                scenario, site=load_site(), prepare=lambda exe: attach_all(exe, [recorder])
            ) as r:
                outcome = await r.finish(120.0)
        finally:
            recorder.close()
        return outcome.code, outcome.reason

    t0 = time.monotonic()
    code, reason = asyncio.run(run())
    return {
        "file": tour.file,
        "code": code,
        "reason": reason,
        "wall_s": round(time.monotonic() - t0, 2),
        "bytes": path.stat().st_size,
    }


def make(
    out: Path, days: int, per_day: int, seed: int, jobs: int = 1, progress: bool = False
) -> dict[str, Any]:
    """Record the season into ``out`` and write ``out/corpus.json``; the manifest."""
    import multiprocessing

    out.mkdir(parents=True, exist_ok=True)
    tours = plan(days, per_day, seed)
    context = multiprocessing.get_context("fork")
    t0 = time.monotonic()
    results = []
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        futures = [pool.submit(record, t, str(out)) for t in tours]
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
        "weights": KINDS,
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
    p.add_argument("--jobs", type=int, default=2, help="tours recorded at once (processes)")
    a = p.parse_args()
    manifest = make(a.out, a.days, a.tours_per_day, a.seed, a.jobs, progress=True)
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
