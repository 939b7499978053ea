"""Every answer carries the security headers, aiohttp's own errors too, and no error
repeats the request's bytes: raw sockets send what no client library would (a header
over aiohttp's 8,190 bytes, a duplicate ``Host``, a control byte in a header). Pins
:class:`frog_bt.live.console.gate.SafeErrors`, which turns aiohttp's protocol into ours."""

from __future__ import annotations

import asyncio
import json
import logging

import pytest
from console_tour import console_tour

from frog_bt.live.console.gate import BARE_HEADERS, PLAIN_503

MARK = b"EchoMark7"


async def exchange(url: str, request: bytes) -> tuple[int, dict[str, str], bytes]:
    """Status, headers and body of the answer to ``request``, written byte for byte."""
    host, port = url.removeprefix("http://").split(":")
    reader, writer = await asyncio.open_connection(host, int(port))
    try:
        writer.write(request)
        raw = await asyncio.wait_for(reader.read(), 30)  # the console closes after an error
    finally:
        writer.close()
    head, _, body = raw.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    headers = dict(line.split(": ", 1) for line in lines[1:] if ": " in line)
    return int(lines[0].split()[1]), headers, body


def test_aiohttps_own_errors_carry_the_headers_and_echo_nothing(
    caplog: pytest.LogCaptureFixture,
) -> None:
    async def main() -> dict[str, tuple[int, dict[str, str], bytes]]:
        async with console_tour(once=False) as (run, people, url):
            port = url.rsplit(":", 1)[1].encode()
            host = b"Host: 127.0.0.1:" + port + b"\r\n"
            tries = {
                "oversized header": b"GET / HTTP/1.1\r\n"
                + host
                + b"X-Big: "
                + MARK * 1200
                + b"\r\n\r\n",
                "oversized line": b"GET /" + MARK * 1200 + b" HTTP/1.1\r\n" + host + b"\r\n",
                "duplicate host": b"GET / HTTP/1.1\r\n" + host + b"Host: " + MARK + b"\r\n\r\n",
                "bad header byte": b"GET / HTTP/1.1\r\n"
                + host
                + b"X-Bad: a\x01"
                + MARK
                + b"\r\n\r\n",
                "bad header name": b"GET / HTTP/1.1\r\n" + host + MARK + b"\x7f: x\r\n\r\n",
                "not http": MARK + b" \x16\x03\x01 hello\r\n\r\n",
            }
            out = {name: await exchange(url, request) for name, request in tries.items()}
            assert people.console is not None
            out["count"] = (people.console.door.errors, {}, b"")
            run.executive.stop("test over")
            return out

    caplog.set_level(logging.DEBUG)
    out = asyncio.run(main())
    count = out.pop("count")[0]
    assert count == len(out)  # each one counted
    for name, (status, headers, body) in out.items():
        assert 400 <= status < 500, (name, status)
        for header, value in BARE_HEADERS.items():
            assert headers.get(header) == value, (name, header, headers)
        assert MARK not in body and MARK.decode() not in str(headers), (name, body)
        answer = json.loads(body)
        assert answer["ok"] is False and answer["reason"].startswith("the request could not")
    logged = "\n".join(r.getMessage() for r in caplog.records)
    assert MARK.decode() not in logged and "answered 400 by the HTTP layer" in logged


def test_the_busy_answer_carries_the_headers_too() -> None:
    head = PLAIN_503.split(b"\r\n\r\n")[0].decode()
    for header, value in BARE_HEADERS.items():
        assert f"\r\n{header}: {value}" in head
    assert head.startswith("HTTP/1.1 503 ") and PLAIN_503.endswith(
        b"the console is busy: try again"
    )
