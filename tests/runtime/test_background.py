"""Background jobs (telemetry's writing) run at a quiet turn of the loop, in order, and
are never starved."""

from __future__ import annotations

import asyncio
import socket
from collections.abc import Awaitable, Callable

from frog_bt.runtime import background


def test_a_job_runs_after_the_callbacks_that_are_due() -> None:
    async def scenario() -> list[str]:
        order: list[str] = []
        loop = asyncio.get_running_loop()
        background.soon(lambda: order.append("job"))
        loop.call_soon(lambda: order.append("input"))
        loop.call_soon(lambda: loop.call_soon(lambda: order.append("its tick")))
        await background.settled()
        return order

    assert asyncio.run(scenario()) == ["input", "its tick", "job"]


async def _an_input_arrives(
    submit: Callable[[list[str]], None],
    settled: Callable[[], Awaitable[None]],
    with_tick: bool,
) -> list[str]:
    """A datagram arrives during a callback that also submits a job (``submit``); the
    order in which the datagram, the tick it calls for (``with_tick``) and the job ran."""
    order: list[str] = []
    loop = asyncio.get_running_loop()

    class Receiver(asyncio.DatagramProtocol):
        def datagram_received(self, data: bytes, addr: object) -> None:
            order.append(data.decode())
            if with_tick:
                loop.call_soon(lambda: order.append("its tick"))

    transport, _ = await loop.create_datagram_endpoint(Receiver, local_addr=("127.0.0.1", 0))
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as peer:

            def arrives_during_a_callback() -> None:
                peer.sendto(b"user_positive", transport.get_extra_info("sockname"))
                submit(order)

            loop.call_soon(arrives_during_a_callback)
            await asyncio.sleep(0)
            await settled()
    finally:
        transport.close()
    return order


def test_a_job_waits_for_a_datagram_that_has_arrived() -> None:
    """Input waiting on a socket goes first, though its callback is not due yet."""

    async def scenario() -> list[str]:
        return await _an_input_arrives(
            lambda order: background.soon(lambda: order.append("job")),
            background.settled,
            with_tick=False,
        )

    assert asyncio.run(scenario()) == ["user_positive", "job"]


def test_a_job_past_the_hold_still_lets_an_input_and_its_tick_go_first() -> None:
    """Ticks at 1 kHz keep a job waiting past ``max_wait`` (the hold gives way), yet an
    input that has arrived, and the tick it calls for, still go before it (its late
    turns)."""

    async def scenario() -> list[str]:
        jobs = background.Background(asyncio.get_running_loop(), max_wait=0.0)

        def submit(order: list[str]) -> None:
            jobs.hold(10.0)  # a tick just ended: its hold, ignored (max_wait 0)
            jobs.call(lambda: order.append("job"))

        return await _an_input_arrives(submit, jobs.settled, with_tick=True)

    assert asyncio.run(scenario()) == ["user_positive", "its tick", "job"]


def test_jobs_run_in_order_and_a_failing_one_is_logged(caplog) -> None:  # type: ignore[no-untyped-def]
    async def scenario() -> list[int]:
        done: list[int] = []
        background.soon(lambda: done.append(1))
        background.soon(lambda: 1 / 0)  # type: ignore[func-returns-value]
        background.soon(lambda: done.append(3))
        await background.settled()
        return done

    assert asyncio.run(scenario()) == [1, 3]
    assert "background job" in caplog.text and "ZeroDivisionError" in caplog.text


def test_a_job_is_not_starved_by_a_loop_that_never_rests() -> None:
    """A loop with a callback always due still runs the job, after ``max_wait`` and
    ``late_turns`` more turns."""

    async def scenario() -> tuple[bool, int, int]:
        loop = asyncio.get_running_loop()
        jobs = background.Background(loop, max_wait=0.002)
        ran: list[bool] = []
        spinning = [True]

        def spin() -> None:
            if spinning[0]:
                loop.call_soon(spin)

        spin()
        jobs.call(lambda: ran.append(True))
        await jobs.settled()
        spinning[0] = False
        return bool(ran), jobs.forced, jobs.waited

    ran, forced, waited = asyncio.run(scenario())
    assert ran and forced == 1 and waited > 0


def test_without_an_event_loop_a_job_runs_at_once() -> None:
    done: list[str] = []
    background.soon(lambda: done.append("now"))
    assert done == ["now"]


def test_after_a_tick_jobs_hold_so_that_the_answer_goes_first() -> None:
    """In the hold after a tick, a job waits (on a timer, the loop free to sleep) and an
    answer that comes meanwhile is served first; the job runs once the hold is over."""

    async def scenario() -> tuple[list[str], float]:
        order: list[str] = []
        loop = asyncio.get_running_loop()
        jobs = background.of(loop)
        jobs.hold(0.003)
        started = loop.time()
        background.soon(lambda: order.append("job"))
        loop.call_later(0.001, lambda: order.append("answer"))  # after the loop slept
        await jobs.settled()
        return order, loop.time() - started

    order, took = asyncio.run(scenario())
    assert order == ["answer", "job"]
    assert took >= 0.002  # it waited for the hold (bounded by MAX_WAIT)
