"""The one clock: manual and sim time wake sleepers in deadline order; time of day in Madrid."""

from __future__ import annotations

import asyncio

import pytest

from frog_bt.clock import ManualClock, SimClock, WallClock


def test_manual_clock_wakes_sleepers_in_deadline_order_and_never_rewinds():
    async def main() -> list[str]:
        clock = ManualClock(100.0)
        woke: list[str] = []

        async def sleeper(name: str, seconds: float) -> None:
            await clock.sleep(seconds)
            woke.append(f"{name}@{clock.now():g}")

        tasks = [asyncio.create_task(sleeper(n, s)) for n, s in [("b", 2), ("a", 1), ("c", 5)]]
        await asyncio.sleep(0)
        assert clock.next_deadline == 101.0
        clock.set(101.5)
        await asyncio.sleep(0)
        clock.set(50.0)  # a stale /clock: ignored
        assert clock.now() == 101.5
        clock.advance(1.0)
        await asyncio.sleep(0)
        assert woke == ["a@101.5", "b@102.5"]
        clock.advance(10)
        await asyncio.gather(*tasks)
        return woke

    assert asyncio.run(main()) == ["a@101.5", "b@102.5", "c@112.5"]


def test_sim_clock_times_nothing_before_the_first_clock_message():
    async def main() -> tuple[bool, bool, float]:
        clock = SimClock()
        assert not clock.ready
        sleeper = asyncio.create_task(clock.sleep(1.0))
        await asyncio.sleep(0)
        early = sleeper.done()
        clock.set(1000.0)  # first /clock: ready, the sleep starts counting now
        await asyncio.sleep(0)
        still_waiting = not sleeper.done()
        clock.set(1001.0)
        await sleeper
        return early, still_waiting, clock.now()

    assert asyncio.run(main()) == (False, True, 1001.0)


@pytest.mark.parametrize(
    ("epoch", "local"),
    [
        (1780302600.0, "2026-06-01 10:30 +0200"),  # summer time
        (1768993200.0, "2026-01-21 12:00 +0100"),  # winter time
    ],
)
def test_time_of_day_is_europe_madrid(epoch, local):
    assert ManualClock(epoch).local_time().strftime("%Y-%m-%d %H:%M %z") == local


def test_wall_clock_is_epoch_aligned_and_monotonic():
    import time

    clock = WallClock()
    a, b = clock.now(), clock.now()
    assert abs(a - time.time()) < 1.0 and b >= a
