"""``frog-bt ctl`` trusts only a clear yes from the console itself: a redirect is not
followed (the token stays home), an answer without ``"ok": true`` is a failure with its
reason, an answer that does not prove it is the console's is refused, no proxy is used
(even with ``http_proxy`` set), and the token does not go over plain http off loopback
without ``--insecure``."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import pytest
from aiohttp import web
from console_tour import TOKEN, console_tour
from test_faults import is_

from frog_bt.cli import main
from frog_bt.commands import ctl
from frog_bt.live.console.acklink import answer_proof, console_id
from frog_bt.model import keys


@web.middleware
async def signed(request: web.Request, handler: Any) -> web.StreamResponse:
    """Answers as the console that holds TOKEN signs them (what ctl checks)."""
    response = await handler(request)
    if isinstance(response, web.Response) and isinstance(response.body, bytes):
        response.headers["X-Frog-Console"] = console_id(TOKEN)
        nonce = request.headers.get("X-Frog-Nonce", "")
        response.headers["X-Frog-Proof"] = answer_proof(TOKEN, nonce, response.body)
    return response


def test_ctl_follows_no_redirect_and_wants_ok_true(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN)
    elsewhere: list[str] = []

    async def redirect(_request: web.Request) -> web.Response:
        raise web.HTTPTemporaryRedirect("/elsewhere/api/command")

    async def steal(request: web.Request) -> web.Response:
        elsewhere.append(request.headers.get("Authorization", ""))
        return web.json_response({"ok": True, "did": "stolen"})

    async def no_ok(_request: web.Request) -> web.Response:
        return web.json_response({"did": "it, trust me"})

    async def not_json(_request: web.Request) -> web.Response:
        return web.Response(text="<html>a captive portal</html>")

    async def refused(_request: web.Request) -> web.Response:
        return web.json_response({"ok": False, "reason": "not now"})

    async def run() -> list[tuple[int, str, str]]:
        app = web.Application(middlewares=[signed])
        for prefix, handler in (
            ("redirect", redirect),
            ("elsewhere", steal),
            ("no-ok", no_ok),
            ("not-json", not_json),
            ("refused", refused),
        ):
            app.router.add_post(f"/{prefix}/api/command", handler)
        runner = web.AppRunner(app)
        await runner.setup()
        site = web.TCPSite(runner, "127.0.0.1", 0)
        await site.start()
        out = []
        try:
            for prefix in ("redirect", "no-ok", "not-json", "refused"):
                argv = ["ctl", "home", "--console", f"http://127.0.0.1:{site.port}/{prefix}"]
                code = await asyncio.to_thread(main, [*argv, "--token-file", str(token)])
                printed = capsys.readouterr()
                out.append((code, printed.out.strip(), printed.err.strip()))
        finally:
            await runner.cleanup()
        return out

    redirected, no_ok_, not_json_, refused_ = asyncio.run(run())
    assert elsewhere == []  # the token never went to the other place
    assert (
        redirected[0] == 2 and "redirects to /elsewhere/api/command: not followed" in redirected[2]
    )
    assert no_ok_[0] == 2 and 'did not say "ok": true' in no_ok_[2] and no_ok_[1] == ""
    assert not_json_[0] == 2 and "not JSON" in not_json_[2]
    assert refused_ == (1, "refused: not now", "")


class Stranger:
    """A loopback server that says yes to everything (a proxy, or whatever answers on the
    port): ``{"ok": true}``, optionally with the console's id copied from its state."""

    def __init__(self, copy_id: str = "", sign: bool = False) -> None:
        self.copy_id, self.sign = copy_id, sign
        self.asked: list[str] = []

    async def answer(self, request: web.Request) -> web.Response:
        self.asked.append(f"{request.method} {request.path_qs}")
        headers = {"X-Frog-Console": self.copy_id} if self.copy_id else {}
        return web.json_response({"ok": True, "did": "nothing at all"}, headers=headers)

    async def __aenter__(self) -> str:
        app = web.Application(middlewares=[signed] if self.sign else [])
        app.router.add_route("*", "/{tail:.*}", self.answer)
        self.runner = web.AppRunner(app)
        await self.runner.setup()
        site = web.TCPSite(self.runner, "127.0.0.1", 0)
        await site.start()
        return f"http://127.0.0.1:{site.port}"

    async def __aexit__(self, *_exc: object) -> None:
        await self.runner.cleanup()


def ctl_process(*argv: str, env: dict[str, str]) -> tuple[int, str, str]:
    """``frog-bt ctl`` in a process of its own, with ``env`` (its proxy variables)."""
    import os
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "frog_bt", "ctl", *argv],
        env={**os.environ, **env},
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    return done.returncode, done.stdout.strip(), done.stderr.strip()


def test_ctl_ignores_proxies_and_refuses_an_answer_that_is_not_the_consoles(
    tmp_path: Path,
) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN)

    async def main() -> dict[str, object]:
        out: dict[str, object] = {}
        proxy, copycat = Stranger(), Stranger(copy_id=console_id(TOKEN))
        async with (
            proxy as proxy_url,
            copycat as copycat_url,
            console_tour(once=False) as (run, _people, url),
        ):
            env = {
                "http_proxy": proxy_url,
                "HTTP_PROXY": proxy_url,
                "https_proxy": proxy_url,
                "no_proxy": "",
                "NO_PROXY": "",
            }
            await run.sim.wait_for(is_("tour", state="started"), 60)
            args = ("--token-file", str(token), "--timeout", "60")
            out["through"] = await asyncio.to_thread(
                ctl_process, "pause", "--console", url, *args, env=env
            )
            out["paused"] = run.executive.core.board.get(keys.PAUSED)
            out["proxy asked"] = list(proxy.asked)
            out["stranger"] = await asyncio.to_thread(
                ctl_process, "resume", "--console", proxy_url, *args, env={}
            )
            out["copycat"] = await asyncio.to_thread(
                ctl_process, "resume", "--console", copycat_url, *args, env={}
            )
            out["status"] = await asyncio.to_thread(
                ctl_process, "status", "--json", "--console", url, *args, env=env
            )
            run.executive.stop("test over")
        return out

    out = asyncio.run(main())
    code, said, err = out["through"]  # type: ignore[misc]
    assert (code, err) == (0, "") and said.startswith("hecho: "), out["through"]
    assert out["proxy asked"] == []  # the token never went to the proxy
    assert out["paused"] is True  # the console itself did it
    code, said, err = out["stranger"]  # type: ignore[misc]
    assert code == 2 and said == "" and "is not from the console that holds this token" in err
    assert "console id missing" in err
    code, said, err = out["copycat"]  # type: ignore[misc]
    assert code == 2 and said == "" and "carries no valid proof of the console" in err
    code, said, err = out["status"]  # type: ignore[misc]
    assert code == 0 and f'"console": "{console_id(TOKEN)}"' in said, err


def test_ctl_sends_no_token_over_plain_http_off_loopback_unless_insecure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN)
    monkeypatch.setattr(ctl, "is_loopback", lambda _host: False)  # as if it were off loopback

    async def probe() -> tuple[list[str], list[tuple[int, str, str]]]:
        console = Stranger(sign=True)  # a console that holds TOKEN
        out = []
        async with console as url:
            for extra in ((), ("--insecure",)):
                argv = ["ctl", "home", "--console", url, "--token-file", str(token), *extra]
                code = await asyncio.to_thread(main, argv)
                printed = capsys.readouterr()
                out.append((code, printed.out.strip(), printed.err.strip()))
        return console.asked, out

    asked, ((refused, _, why), (sent, said, warned)) = asyncio.run(probe())
    assert refused == 2 and "plain http to a host that is not loopback" in why
    assert "give --insecure" in why and asked == ["POST /api/command"]  # only the second
    assert sent == 0 and said == "done: nothing at all"
    assert warned == (
        "frog-bt ctl: warning: --insecure: the token goes in clear over plain http to 127.0.0.1"
    )
