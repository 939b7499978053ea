"""Tick cost of the tour tree, phase by phase, for one tour size, telemetry off or on.

One whole tour of a synthetic site with ``--stops`` stops runs in this process: the
built-in simulator and the real executive in one event loop, on sim time (as the
end-to-end tests run them). Every ``Core.tick`` is timed with ``perf_counter_ns``
(snapshot, tree, taps: everything a tick costs, telemetry and recording taps
included when on) and filed under the phase the tree is in after it, read off the
leaf at the tip of the running path.

    .venv/bin/python scripts/bench_ticks.py --stops 30 --telemetry on
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import resource
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import (
    emit,
    free_port,
    scenario,
    small_log,
    summary_us,
    synthetic_site,
)

RECRUIT = {
    "SeekVisitor",
    "ApproachVisitor",
    "StartIntroduction",
    "AskTour",
    "WaitAnswer",
    "WaitEvent",
}
CONTENT = {"VisitorFollows", "PlayContent", "FinishPoi", "Engaged", "SkipStop", "Skipped"}
PHASES = ("waiting", "undocking", "recruiting", "driving", "content", "returning", "other")

# Short content and a fast clock (as the end-to-end tests), but long enough phases for
# percentiles: the front end says idle after 20 s, the visitor turns up after 60 s.
SCENARIO: dict[str, Any] = {
    "speed": 400.0,
    "content": {"default": 10, "introduction": 8},
    "frontend": {"idle_at": 20.0},
    "visitors": [
        {
            "id": 7,
            "position": [103.0, 36.0],
            "facing": True,
            "answer": "positive",
            "faces": "engaged",
            "follow": True,
            "after_tour": "leave",
            "appear_at": 60.0,
        }
    ],
}


class _Probe:
    """Stands for a core's ``emit`` (the host's Observers) and times what the observers do
    while a tick runs (``inside``): the events the tick tells them, and a last tick's end
    still held when the next one starts (``settle``). Also the garbage collector's time
    inside ticks. Only with ``--probe``: it adds a little to every call it times."""

    def __init__(self, observers: Any, clock: Any) -> None:
        self.observers = observers
        self.clock = clock
        self.inside = False
        self.emit_ns: list[int] = []  # per tick: observers' time inside it
        self.gc_ns: list[int] = []  # per tick: the collector's time inside it
        self._emit = 0
        self._gc = 0
        self.by_kind: dict[str, int] = defaultdict(int)  # ns inside ticks: emit, settle, later
        self.settled = 0  # ticks that began by telling a last tick's end still held
        self._gc0 = 0
        gc.callbacks.append(self._collecting)

    def _collecting(self, phase: str, info: dict[str, Any]) -> None:
        if not self.inside:
            return
        if phase == "start":
            self._gc0 = self.clock()
        else:
            self._gc += self.clock() - self._gc0

    def __bool__(self) -> bool:
        return bool(self.observers)

    def __call__(self, event: Any) -> None:
        t0 = self.clock()
        self.observers.emit(event)
        self._count("emit", self.clock() - t0)

    def settle(self) -> None:
        held = bool(self.observers._later)
        t0 = self.clock()
        self.observers.settle()
        self._count("settle", self.clock() - t0)
        if held and self.inside:
            self.settled += 1

    def later(self, event: Any) -> None:
        t0 = self.clock()
        self.observers.later(event)
        self._count("later", self.clock() - t0)

    def _count(self, kind: str, ns: int) -> None:
        if self.inside:
            self._emit += ns
            self.by_kind[kind] += ns

    def start(self) -> None:
        self.inside, self._emit, self._gc = True, 0, 0

    def end(self) -> None:
        self.inside = False
        self.emit_ns.append(self._emit)
        self.gc_ns.append(self._gc)


class _Pauses:
    """The collector's pauses over the tour (wall time), by generation."""

    def __init__(self) -> None:
        self.ns: dict[int, list[int]] = defaultdict(list)
        self._t0 = 0
        gc.callbacks.append(self._collecting)

    def _collecting(self, phase: str, info: dict[str, Any]) -> None:
        if phase == "start":
            self._t0 = time.perf_counter_ns()
        else:
            self.ns[info["generation"]].append(time.perf_counter_ns() - self._t0)

    def summary(self) -> dict[str, Any]:
        gc.callbacks.remove(self._collecting)
        return {
            str(g): {"n": len(v), "max_ms": max(v) / 1e6, "total_ms": sum(v) / 1e6}
            for g, v in sorted(self.ns.items())
        }


class _Null:
    """An observer that hears every event and does nothing with it."""

    def attach(self, host: Any) -> None:
        pass

    def on_event(self, event: Any) -> None:
        pass

    def close(self) -> None:
        pass


def phase_of(node: Any, dock: str, recruit_at: str) -> str:
    kind = type(node).__name__
    if kind in ("WaitFrontendIdle", "ConfirmResume"):
        return "waiting"
    if kind == "Docking":
        return "undocking" if node.params.action == "undock" else "returning"
    if kind in RECRUIT:
        return "recruiting"
    if kind == "DecideEngagement":
        return "recruiting" if node.params.about == "introduction" else "content"
    if kind == "Navigate":
        return "returning" if node.params.poi == dock else "driving"
    if kind in CONTENT:
        return "content"
    if kind == "TourStatus":
        return "returning" if node.params.state != "started" else "undocking"
    return "other"


async def one_tour(
    stops: int, telemetry: str, workdir: Path, probe: bool = False
) -> dict[str, Any]:
    from frog_bt.behaviours import load_tree
    from frog_bt.clock import SimClock
    from frog_bt.config import load_site
    from frog_bt.rehearsal import links_to
    from frog_bt.runtime.executive import Executive
    from frog_bt.runtime.exits import ExitRules
    from frog_bt.sim import Simulator
    from frog_bt.sim.site import load_pois

    site_path = synthetic_site(stops, workdir)
    site = load_site(site_path)
    tree = load_tree(site=site)
    nodes = sum(1 for _ in tree.nodes())
    listen = ("127.0.0.1", free_port())
    sim = Simulator(
        scenario(SCENARIO),
        rosbridge_port=0,
        frontend_port=0,
        executive=listen,
        pois=load_pois(site_path),
    )
    small_log(sim)
    await sim.start()
    clock = SimClock()
    executive = Executive(site, tree, clock, *links_to(sim, listen, clock), sim_time=True)
    rules = ExitRules(once=True)
    executive.observers.attach(executive, [rules])
    from frog_bt.runtime import memory as heap

    freeze = getattr(heap, "freeze_heap", None)
    if freeze is not None:  # as `frog-bt run` does once loaded (the code before: nothing)
        freeze()
    # What `frog-bt run` does with telemetry or without (off is the executive as it runs,
    # not a bare one): malloc's thresholds pinned, the collector at quiet turns.
    pin = getattr(heap, "pin_malloc_thresholds", None)
    if pin is not None:
        pin()
    quiet = getattr(heap, "QuietCollector", None)
    if quiet is not None:
        from frog_bt.runtime.observer import attach_all as attach_quiet

        attach_quiet(executive, [quiet()])
    pauses = _Pauses()
    observers: list[Any] = []
    writes: list[int] = []
    if telemetry == "null":  # an observer that does nothing: what listening alone costs
        from frog_bt.runtime.observer import attach_all

        observers = attach_all(executive, [_Null()])
    elif telemetry != "off":  # as frog-bt run --record FILE --rerun save:FILE attaches them
        from frog_bt.commands.run import attach_observers

        observers = attach_observers(
            executive,
            record=workdir / "ticks.mcap" if telemetry != "rerun" else None,
            rerun=f"save:{workdir / 'ticks.rrd'}" if telemetry != "record" else None,
        )
        tel = observers[-1]
        if hasattr(tel, "_next_step"):  # written in-process (no fork): time its steps too
            plain_step = tel._next_step

            def timed_step() -> bool:
                t0 = time.perf_counter_ns()
                more = plain_step()
                writes.append(time.perf_counter_ns() - t0)
                return more

            tel._next_step = timed_step  # type: ignore[method-assign]

    core = executive.core
    inner = core.tick
    samples: dict[str, list[int]] = defaultdict(list)
    phases: dict[int, str] = {}
    dock, recruit_at = site.tour.dock, site.tour.recruit_at
    clock = time.thread_time_ns  # the tick thread's CPU time: not the time others took
    probing = _Probe(core.emit, clock) if probe else None
    if probing is not None:
        core.emit = probing  # type: ignore[assignment]

    def timed_tick() -> Any:
        if probing is not None:
            probing.start()
        t0 = clock()
        status = inner()
        dt = clock() - t0
        if probing is not None:
            probing.end()
        tip = core.root.tip()
        phase = phases.get(id(tip))
        if phase is None:
            phase = phases[id(tip)] = phase_of(tip, dock, recruit_at)
        samples[phase].append(dt)
        return status

    core.tick = timed_tick  # type: ignore[method-assign]
    sim0, wall0 = sim.clock.now(), time.monotonic()
    try:
        outcome = await asyncio.wait_for(executive.run(), 600)
    finally:
        await sim.stop()
        close0 = time.perf_counter()
        children0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        for observer in observers:
            observer.close()
        children1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        close_s = time.perf_counter() - close0
        sizes = {
            f.name: f.stat().st_size for f in workdir.iterdir() if f.suffix in (".rrd", ".mcap")
        }
    wall = time.monotonic() - wall0
    t0 = time.thread_time_ns()
    gc.collect()
    full_ms = (time.thread_time_ns() - t0) / 1e6
    every = [dt for values in samples.values() for dt in values]
    # Telemetry's phases: on the tick (its taps: the overhead above), then after the tick
    # serialise and hand over (this process), then write (the writer child, its CPU time).
    handover: dict[str, Any] = {}
    timings = getattr(observers[-1], "timings", None) if observers else None
    if timings is not None:
        batches = len(timings.serialise)
        child_s = (children1.ru_utime + children1.ru_stime) - (
            children0.ru_utime + children0.ru_stime
        )
        handover = {
            "batches": batches,
            "serialise": summary_us(timings.serialise),  # a batch's pieces, summed
            # one step of it (STEP_ROWS rows): the longest an input waits for it
            "serialise_step": summary_us(getattr(timings, "serialise_step", ())),
            "hand_over": summary_us(timings.hand_over),
            "write_child_cpu_s": child_s,
            "write_us_per_batch": child_s * 1e6 / max(1, batches),
            "after_tick_us_per_tick": (sum(timings.serialise) + sum(timings.hand_over))
            / 1e3
            / max(1, len(every)),
        }
    return {
        "stops": stops,
        "telemetry": telemetry,
        "nodes": nodes,
        "outcome": outcome.reason,
        "tours": rules.tours,
        "sim_s": sim.clock.now() - sim0,
        "wall_s": wall,
        "observers_close_s": close_s if observers else 0.0,
        "all": summary_us(every),
        "phases": {p: summary_us(samples[p]) for p in PHASES if samples.get(p)},
        "telemetry_writes": summary_us(writes),  # steps of writing rows to rerun
        "telemetry_write_us_per_tick": sum(writes) / 1e3 / max(1, len(every)),
        "telemetry_phases": handover,
        "telemetry_dropped_batches": getattr(observers[-1], "dropped", 0) if observers else 0,
        "file_bytes": sizes,  # the recording and the .rrd of the tour
        "gc_collections": [s["collections"] for s in gc.get_stats()],
        "gc_pauses": pauses.summary(),  # the whole tour, in ticks or between them
        "full_collection_ms": full_ms,  # what one would cost the loop at the tour's end
        **(
            {
                "probe": {
                    "observers_in_tick": summary_us(probing.emit_ns),
                    "observers_in_tick_us_per_tick": sum(probing.emit_ns) / 1e3 / len(every),
                    "gc_in_tick": summary_us(probing.gc_ns),
                    "gc_in_tick_us_per_tick": sum(probing.gc_ns) / 1e3 / len(every),
                    "ticks_with_gc": sum(1 for g in probing.gc_ns if g) / len(every),
                    "in_tick_us_per_tick_by_call": {
                        k: v / 1e3 / len(every) for k, v in probing.by_kind.items()
                    },
                    "ticks_settling_a_held_end": probing.settled / len(every),
                }
            }
            if probing is not None
            else {}
        ),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--stops", type=int, default=7)
    p.add_argument(
        "--telemetry",
        choices=("on", "off", "record", "rerun", "null"),
        default="off",
        help="on: --record FILE and --rerun save:FILE.rrd; or either alone",
    )
    p.add_argument(
        "--probe",
        action="store_true",
        help="also time the observers' work and the garbage collector inside the ticks",
    )
    p.add_argument("--out", help="write the JSON result here (default: stdout)")
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
        result = asyncio.run(one_tour(args.stops, args.telemetry, Path(tmp), args.probe))
    emit(result, args.out)


if __name__ == "__main__":
    main()
