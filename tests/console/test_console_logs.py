"""Each console shows its own executive's log lines: two executives with consoles in one
process, each page's log has its executive's lines and neither the other's nor the lines
logged around them (:mod:`frog_bt.runtime.logctx`)."""

from __future__ import annotations

import asyncio
import logging

import aiohttp
from console_tour import command, console_tour
from test_faults import is_

from frog_bt.live.console.state import LogLines
from frog_bt.runtime import logctx

log = logging.getLogger("frog_bt.tests.console")


def test_a_handler_keeps_the_lines_of_its_owner_and_of_the_tasks_it_started() -> None:
    a, b = object(), object()
    lines_a, lines_b = LogLines(a), LogLines(b)

    async def executive(owner: object, name: str) -> None:
        logctx.mark(owner)
        log.warning("%s itself", name)
        await asyncio.create_task(child(name))  # a task it starts copies its context
        await asyncio.to_thread(log.warning, "%s in a thread", name)

    async def child(name: str) -> None:
        log.warning("%s's child", name)

    async def main() -> None:
        await asyncio.gather(executive(a, "a"), executive(b, "b"))
        log.warning("nobody's")  # the gathered tasks' marks stay in their own contexts
        logctx.run_as(b, lambda: log.warning("b's, from outside"))

    for handler in (lines_a, lines_b):
        log.addHandler(handler)
    try:
        asyncio.run(main())
    finally:
        for handler in (lines_a, lines_b):
            log.removeHandler(handler)
    assert [line.split(": ", 1)[1] for line in lines_a.lines] == [
        "a itself",
        "a's child",
        "a in a thread",
    ]
    assert [line.split(": ", 1)[1] for line in lines_b.lines] == [
        "b itself",
        "b's child",
        "b in a thread",
        "b's, from outside",
    ]
    assert logctx.owner() is None


def test_two_executives_in_one_process_each_console_shows_only_its_own_log() -> None:
    async def logs(session: aiohttp.ClientSession, url: str) -> list[str]:
        async with session.get(f"{url}/api/state") as r:
            body = await r.json()
        return [str(line) for line in body["log"]]

    async def main() -> tuple[list[str], list[str]]:
        async with console_tour() as (one, _p1, url1), console_tour() as (two, _p2, url2):
            await asyncio.gather(
                one.sim.wait_for(is_("tour", state="started"), 60),
                two.sim.wait_for(is_("tour", state="started"), 60),
            )
            log.warning("the test's own line")  # no executive's
            async with aiohttp.ClientSession() as s:
                # both refused, so neither tour changes; the staff logs each as it applies it
                assert (await command(s, url1, {"command": "resume"}))[0] == 409
                assert (await command(s, url2, {"command": "ack_alert", "id": "only-two"}))[
                    0
                ] == 409
                return await logs(s, url1), await logs(s, url2)

    first, second = asyncio.run(main())
    assert any("operator resume: refused: " in line for line in first), first
    assert any("no alert 'only-two' to acknowledge" in line for line in second), second
    assert not any("only-two" in line for line in first), first
    assert not any("operator resume" in line for line in second), second
    assert not any("the test's own line" in line for line in first + second)
