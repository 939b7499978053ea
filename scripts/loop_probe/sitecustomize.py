"""What held a ``frog-bt run``'s event loop, in the thread's CPU time (not wall time: what
other processes took does not count), and the cyclic collector's pauses.

Loaded by ``bench_reaction.py --probe`` (``PYTHONPATH=scripts/loop_probe``): only in a
process whose ``LOOP_PROBE_OUT`` is set and whose command is ``run``. Each callback the
loop runs (asyncio's ``Handle._run``) is timed with ``time.thread_time_ns``; at exit the
process writes ``LOOP_PROBE_OUT.<pid>``: per callback, how many took over 0.5 ms and
the longest; per generation, the collector's pauses after the first second.
"""

import atexit
import gc
import json
import os
import sys
import time

_OUT = os.environ.get("LOOP_PROBE_OUT")

if _OUT and "run" in sys.argv[1:2]:
    import asyncio.events

    _started = time.monotonic()
    _gc: list[tuple[int, int, float]] = []  # generation, ns, seconds since the start
    _gc0 = [0]
    _slow: dict[str, list[float]] = {}
    _total: dict[str, int] = {}

    def _collecting(phase: str, info: dict) -> None:  # type: ignore[type-arg]
        if phase == "start":
            _gc0[0] = time.perf_counter_ns()
        else:
            pause = time.perf_counter_ns() - _gc0[0]
            _gc.append((info["generation"], pause, time.monotonic() - _started))

    gc.callbacks.append(_collecting)
    _run = asyncio.events.Handle._run

    def _timed(self: asyncio.events.Handle) -> None:
        t0 = time.thread_time_ns()
        try:
            _run(self)
        finally:
            ns = time.thread_time_ns() - t0
            cb = self._callback
            name = getattr(cb, "__qualname__", None) or type(cb).__name__
            coro = getattr(getattr(cb, "__self__", None), "_coro", None)
            if coro is not None:
                name += ":" + getattr(coro, "__qualname__", "?")
            _total[name] = _total.get(name, 0) + ns
            if ns > 500_000:
                _slow.setdefault(name, []).append(ns / 1e6)

    asyncio.events.Handle._run = _timed  # type: ignore[method-assign]

    def _write() -> None:
        after = [(g, ns) for g, ns, t in _gc if t > 1.0]
        result = {
            "slow_ms": {k: {"n": len(v), "max": max(v)} for k, v in _slow.items()},
            "busy_ms": {k: v / 1e6 for k, v in sorted(_total.items(), key=lambda kv: -kv[1])[:12]},
            "gc_after_1s": {
                str(g): {
                    "n": sum(1 for x, _ in after if x == g),
                    "max_ms": max((ns for x, ns in after if x == g), default=0) / 1e6,
                }
                for g in (0, 1, 2)
            },
        }
        with open(f"{_OUT}.{os.getpid()}", "w") as f:
            json.dump(result, f)

    atexit.register(_write)
