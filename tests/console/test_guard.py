"""The console as an attacker probes it, over real sockets on loopback: foreign ``Host``
and ``Origin`` get 403, only ``Bearer`` counts, any header bytes give a 4xx, failed
attempts are throttled and logged once, bad bodies give 400, and every answer carries
the security headers. Each of these answered otherwise before issue 28."""

from __future__ import annotations

import asyncio
import json
import re

import aiohttp
import pytest
from console_tour import TOKEN, auth, console_tour
from test_faults import is_

from frog_bt.live.console.origins import Origins
from frog_bt.live.console.server import ACCESS
from frog_bt.live.console.throttle import FAIL_BURST, Rates
from frog_bt.model import keys


def test_origins_are_the_bound_names_and_the_configured_one() -> None:
    origins = Origins("127.0.0.1", "https://frog-1.museum.example")
    origins.bound(8080)
    ok = origins.host_ok
    assert ok("127.0.0.1:8080", None) and ok("localhost:8080", None) and ok("[::1]:8080", None)
    assert ok("LOCALHOST:8080", None) and ok("frog-1.museum.example", None)
    assert not ok("evil.example:8080", None) and not ok("127.0.0.1:9999", None)
    assert not ok("127.0.0.2:8080", None) and not ok("127.0.0.1", None) and not ok("", None)
    assert not ok("127.0.0.1:8080/x", None) and not ok("a@127.0.0.1:8080", None)
    assert ok(None, None)  # not a browser
    wide = Origins("0.0.0.0")
    wide.bound(8080)
    assert wide.host_ok("192.168.1.20:8080", "192.168.1.20")  # the address it was reached at
    assert not wide.host_ok("frog.evil.example:8080", "192.168.1.20")
    o = origins.origin_ok
    assert o("http://127.0.0.1:8080", None) and o("https://frog-1.museum.example", None)
    assert o(None, None)  # ctl and scripts send none
    assert not o("null", None) and not o("http://127.0.0.1:9999", None)
    assert not o("http://127.0.0.2:8080", None) and not o("http://evil.example", None)
    assert not o("http://u@127.0.0.1:8080", None) and not o("file://", None)


async def raw(url: str, request: bytes) -> int:
    """The status of a request written byte for byte (what aiohttp's client won't send)."""
    host, port = url.removeprefix("http://").split(":")
    reader, writer = await asyncio.open_connection(host, int(port))
    try:
        writer.write(request)
        line = await asyncio.wait_for(reader.readline(), 10)
        return int(line.split()[1])
    finally:
        writer.close()


def test_foreign_host_origin_schemes_bytes_bodies_and_headers(
    caplog: pytest.LogCaptureFixture,
) -> None:
    async def main() -> dict[str, object]:
        out: dict[str, object] = {}
        async with console_tour() as (run, people, url):
            assert people.console is not None
            access = people.console.app[ACCESS]
            access.rates = Rates(1000.0)  # not about the command rate
            await run.sim.wait_for(is_("tour", state="started"), 60)
            port = url.rsplit(":", 1)[1]
            async with aiohttp.ClientSession() as s:

                async def get(path: str, **headers: str) -> int:
                    async with s.get(f"{url}{path}", headers=headers) as r:
                        return r.status

                async def post(body: bytes, **headers: str) -> int:
                    async with s.post(f"{url}/api/command", data=body, headers=headers) as r:
                        await r.read()
                        return r.status

                evil = {"Host": "evil.example"}
                out["rebound"] = [await get(p, **evil) for p in ("/", "/api/state", "/api/tree")]
                out["names"] = [
                    await get("/api/state", Host=f"{name}:{port}")
                    for name in ("127.0.0.1", "localhost", "[::1]")
                ]
                foreign = {"Origin": f"http://127.0.0.1:{int(port) + 1}"}
                other = {"Origin": f"http://127.0.0.2:{port}"}
                own = {"Origin": url}
                with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                    await s.ws_connect(f"{url}/api/stream", headers=foreign)
                with pytest.raises(aiohttp.WSServerHandshakeError):
                    await s.ws_connect(f"{url}/api/stream", headers=evil)
                out["stream"] = refused.value.status
                async with s.ws_connect(f"{url}/api/stream", headers=own, compress=15) as ws:
                    assert "phase" in await ws.receive_json()
                    out["compressed"] = ws.compress
                home = json.dumps({"command": "home"}).encode()
                out["origins"] = [
                    await post(home, **auth(), **foreign),
                    await post(home, **auth(), **other),
                    await post(json.dumps({"command": "resume"}).encode(), **auth(), **own),
                ]
                out["schemes"] = [
                    await post(home, Authorization=f"{scheme} {TOKEN}")
                    for scheme in ("Basic", "Token", "X", "")
                ]
                out["bodies"] = [
                    await post(b"[" * 2000 + b"]" * 2000, **auth()),
                    await post(
                        home, **auth(), **{"Content-Type": "application/json; charset=bogus"}
                    ),
                    await post(b'{"command": "\xff"}', **auth()),
                ]
                head = f"POST /api/command HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n".encode()
                tail = b"Content-Length: 2\r\nConnection: close\r\n\r\n{}"
                out["bytes"] = [
                    await raw(url, head + b"Authorization: Bearer \xff\xfe\x80token\r\n" + tail),
                    await raw(url, head + b"Authorization: \xc3\x28\r\n" + tail),
                    await raw(url, head + b"Origin: http://\xff\r\n" + tail),
                    await raw(
                        url, b"GET / HTTP/1.1\r\nHost: \xff\xfe:" + port.encode() + b"\r\n\r\n"
                    ),
                ]
                # a burst of wrong tokens: throttled, but not the right one; one log line
                access.failures.buckets.clear()
                access.failures.logged_at = None  # a minute since the last line
                caplog.clear()
                wrong = [await post(home, **auth("wrong-token-wrong")) for _ in range(30)]
                resume = json.dumps({"command": "resume"}).encode()  # through: 409, not paused
                out["burst"] = (wrong.count(401), wrong.count(429), await post(resume, **auth()))
                out["failure_lines"] = [
                    r.getMessage()
                    for r in caplog.records
                    if "failed token attempt" in r.getMessage()
                ]
                async with s.get(f"{url}/") as r:
                    out["page_headers"] = dict(r.headers)
                async with s.get(f"{url}/console.js") as r:
                    out["script_type"] = r.headers["Content-Type"]
                async with s.get(f"{url}/nowhere") as r:
                    out["missing_headers"] = (r.status, "Content-Security-Policy" in r.headers)
            out["home"] = run.executive.core.board.get(keys.HOME)
            run.executive.stop("test over")
        return out

    out = asyncio.run(main())
    assert out["rebound"] == [403, 403, 403]
    assert out["names"] == [200, 200, 200]
    assert out["stream"] == 403 and out["compressed"] == 0
    assert out["origins"] == [403, 403, 409]
    assert out["schemes"] == [401, 401, 401, 401]
    assert out["bodies"] == [400, 400, 400]
    assert all(400 <= status < 500 for status in out["bytes"]), out["bytes"]  # type: ignore[attr-defined]
    assert out["burst"] == (FAIL_BURST, 30 - FAIL_BURST, 409)
    assert len(out["failure_lines"]) == 1, out["failure_lines"]  # type: ignore[arg-type]
    assert re.fullmatch(
        r"console: \d+ failed token attempts?, \d+ of them answered 429 \(from 127\.0\.0\.1 \d+\)",
        out["failure_lines"][0],  # type: ignore[index]
    )
    headers = out["page_headers"]
    assert isinstance(headers, dict)
    assert "default-src 'self'" in headers["Content-Security-Policy"]
    assert "frame-ancestors 'none'" in headers["Content-Security-Policy"]
    assert "unsafe-inline" not in headers["Content-Security-Policy"]
    assert headers["X-Content-Type-Options"] == "nosniff"
    assert out["script_type"].startswith("text/javascript")  # type: ignore[union-attr]
    assert out["missing_headers"] == (404, True)
    assert out["home"] is None  # nothing above sent the robot home
