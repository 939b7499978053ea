"""Run by ``test_descriptors.py`` in its own process, under a low ``RLIMIT_NOFILE``: a
simulated tour with its console, while the parent holds connections to it.

Prints the console's URL, waits for ``held`` on stdin, lets the tour end, prints
``ended``, waits for ``closed``, reads ``/api/state`` and prints one JSON line: the
outcome, the largest event-loop lag seen, the connections the door refused, the state's
status, and how many log lines and tracebacks went to the log.
"""

from __future__ import annotations

import asyncio
import json
import logging
import resource
import sys
from pathlib import Path

HERE = Path(__file__).parent
sys.path[:0] = [str(HERE), str(HERE.parent / "e2e")]

import aiohttp  # noqa: E402
from console_tour import console_tour  # noqa: E402


class Count(logging.Handler):
    def __init__(self) -> None:
        super().__init__()
        self.lines = 0
        self.tracebacks = 0
        self.out_of_files = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.lines += 1
        self.tracebacks += record.exc_info is not None
        self.out_of_files += "out of file descriptors" in record.getMessage()


async def main(limit: int) -> dict[str, object]:
    _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (limit, hard))
    count = Count()
    logging.getLogger().addHandler(count)
    loop = asyncio.get_running_loop()
    lag = [0.0]

    async def watch() -> None:  # how late the loop wakes a 20 ms sleeper
        while True:
            start = loop.time()
            await asyncio.sleep(0.02)
            lag[0] = max(lag[0], loop.time() - start - 0.02)

    async with console_tour({"speed": 200.0}, once=True) as (run, people, url):
        assert people.console is not None
        watcher = loop.create_task(watch())
        print(url, flush=True)
        await loop.run_in_executor(None, sys.stdin.readline)  # held
        outcome = await run.finish(120)
        print("ended", flush=True)
        await loop.run_in_executor(None, sys.stdin.readline)  # closed
        async with aiohttp.ClientSession() as s, s.get(f"{url}/api/state") as r:
            status = r.status
        watcher.cancel()
        return {
            "code": outcome.code,
            "reason": outcome.reason,
            "tours": outcome.tours,
            "lag": lag[0],
            "cap": people.console.door.cap,
            "refused": people.console.door.refused,
            "state": status,
            "lines": count.lines,
            "tracebacks": count.tracebacks,
            "out_of_files": count.out_of_files,
        }


if __name__ == "__main__":
    print(json.dumps(asyncio.run(main(int(sys.argv[1])))), flush=True)
