"""``frog-bt ctl`` trusts only a clear yes: a redirect is not followed (the token stays
home), and an answer without ``"ok": true`` is a failure with its reason."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from aiohttp import web
from console_tour import TOKEN

from frog_bt.cli import main


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
        app = web.Application()
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
