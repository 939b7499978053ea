"""The console bounded under load: a cap on connections and on pages (plain 503 beyond),
a header-read deadline, a stuck page dropped without holding up the others, the tree
serialised once per tick however often it is read, and running out of descriptors as
one log line, not a traceback per attempt."""

from __future__ import annotations

import asyncio
import errno
import socket
from typing import Any

import aiohttp
import pytest
from console_tour import TOKEN, console_tour
from test_faults import is_

from frog_bt.live.console import server
from frog_bt.live.console.gate import PLAIN_503, OutOfFiles
from frog_bt.live.console.server import PAGES, Console
from frog_bt.live.console.stream import Page, Pages, write


async def first_line(port: int, send: bytes = b"") -> bytes:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        writer.write(send)
        return await asyncio.wait_for(reader.read(), 10)  # the console closes at once
    finally:
        writer.close()


def test_caps_deadline_and_a_cached_tree(monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[int] = []
    real_tree = server.tree

    def counted(root: Any) -> Any:
        made.append(1)
        return real_tree(root)

    monkeypatch.setattr(server, "tree", counted)

    async def main() -> dict[str, object]:
        out: dict[str, object] = {}
        async with console_tour() as (run, people, url):
            console = people.console
            assert console is not None and console.bound_port is not None
            await run.sim.wait_for(is_("tour", state="started"), 60)
            async with aiohttp.ClientSession() as s:
                console.app[PAGES].max_pages = 2
                async with s.ws_connect(f"{url}/api/stream"), s.ws_connect(f"{url}/api/stream"):
                    with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                        await s.ws_connect(f"{url}/api/stream")
                    out["third page"] = refused.value.status
                console.door.cap = console.door.open  # full: the next connection is refused
                out["over the cap"] = await first_line(console.bound_port)
                console.door.cap = 512
                ticks = run.executive.core.ticks
                for _ in range(50):
                    async with s.get(f"{url}/api/tree") as r:
                        assert r.status == 200
                out["trees made"] = (len(made), run.executive.core.ticks - ticks + 1)
                shown, core = console.app[server.SHOWN], run.executive.core
                made.clear()
                between = [
                    shown.cache("tree", core, core.ticks, lambda: counted(core.root))
                    for _ in range(3)
                ]  # no tick between these reads: made once
                out["between ticks"] = (len(made), between[0] is between[2])
            # a console with a short header deadline: a slow header is cut off
            quick = Console(run.executive, "127.0.0.1", 0, TOKEN, header_timeout=0.3)
            await quick.start()
            try:
                assert quick.bound_port is not None
                out["slow header"] = await first_line(quick.bound_port, b"GET / HTTP/1.1\r\nHo")
                host = f"Host: 127.0.0.1:{quick.bound_port}".encode()
                out["whole header"] = await first_line(
                    quick.bound_port, b"GET /api/state HTTP/1.1\r\n" + host + b"\r\n\r\n"
                )
            finally:
                await quick.close()
            run.executive.stop("test over")
        return out

    out = asyncio.run(main())
    assert out["third page"] == 503
    assert out["over the cap"] == PLAIN_503
    made_, bound = out["trees made"]  # type: ignore[misc]
    assert made_ <= bound  # once per tick at most, not once per read
    assert out["between ticks"] == (1, True)
    assert out["slow header"] == b""  # closed, nothing answered
    assert bytes(out["whole header"]).startswith(b"HTTP/1.1 200")  # type: ignore[arg-type]


class StuckSocket:
    """A page that never takes what is sent to it."""

    def __init__(self) -> None:
        self.aborted = False

    async def send_str(self, _text: str) -> None:
        await asyncio.Event().wait()


class Reader:
    """A page that takes everything at once."""

    def __init__(self) -> None:
        self.got: list[str] = []
        self.more = asyncio.Event()

    async def send_str(self, text: str) -> None:
        self.got.append(text)
        self.more.set()


def test_a_stuck_page_is_dropped_and_holds_up_nobody() -> None:
    async def main() -> tuple[list[str], bool, int, int]:
        pages = Pages(push_every=0.3, send_timeout=0.2)
        stuck_ws, reader = StuckSocket(), Reader()
        stuck = Page(stuck_ws, lambda: setattr(stuck_ws, "aborted", True))  # type: ignore[arg-type]
        good = Page(reader, lambda: None)  # type: ignore[arg-type]
        pages.open.update({stuck, good})
        tasks = [asyncio.create_task(write(pages, page)) for page in (stuck, good)]
        for text in ("one", "two", "three"):
            pages.offer(text)
            async with asyncio.timeout(0.1):  # well within the stuck page's timeout
                await reader.more.wait()
            reader.more.clear()
        async with asyncio.timeout(5):
            await tasks[0]  # the stuck page's writer ends: dropped
        tasks[1].cancel()
        return reader.got, stuck_ws.aborted, len(pages.open), pages.dropped

    got, aborted, still_open, dropped = asyncio.run(main())
    assert got == ["one", "two", "three"]
    assert aborted and still_open == 1 and dropped == 1


class Wrapped:
    def __init__(self, fileno: int) -> None:
        self._fileno = fileno

    def fileno(self) -> int:
        return self._fileno


def test_out_of_descriptors_is_one_line_not_a_traceback_per_attempt(
    caplog: pytest.LogCaptureFixture,
) -> None:
    loop = asyncio.new_event_loop()
    others: list[dict[str, Any]] = []
    loop.set_exception_handler(lambda _loop, context: others.append(context))
    listening = socket.socket()
    try:
        handler = OutOfFiles(loop, [listening])
        for _ in range(1000):
            loop.call_exception_handler(
                {
                    "message": "socket.accept() out of system resource",
                    "exception": OSError(errno.EMFILE, "Too many open files"),
                    "socket": Wrapped(listening.fileno()),  # asyncio's wrapper, new each time
                }
            )
        loop.call_exception_handler({"message": "something else"})
        handler.close()
        assert loop.get_exception_handler() is not handler
    finally:
        listening.close()
        loop.close()
    lines = [r for r in caplog.records if r.name == "frog_bt.live.console.gate"]
    assert [r.getMessage() for r in lines] == [
        "console: out of file descriptors (EMFILE): 1 connection not accepted; "
        "asyncio retries each second"
    ]
    assert all(r.exc_info is None for r in lines)
    assert [c["message"] for c in others] == ["something else"]
