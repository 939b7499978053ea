"""The console in Chromium, attacked: a fault whose ``/diagnostic`` message is markup
with script is shown as text and runs nothing; a page served from another loopback
address and port can neither read the stream nor send a command.

Skipped (saying why) without Debian's chromium and chromium-driver, except in CI.
"""

from __future__ import annotations

import asyncio
import json
from typing import Any

import aiohttp
from aiohttp import web
from console_tour import console_tour
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait
from test_browser import WAIT, browser  # skips this module too where no browser runs

from frog_bt.model import keys

SCRIPT = (
    "<img src=x onerror=\"window.pwned=1;document.title='pwned'\"><script>window.pwned=2</script>"
)
FAULT = {"at": 0, "name": "motors", "level": 2, "message": SCRIPT, "duration": 10**6}

FOREIGN = """<!doctype html><html><head><title>foreign</title></head><body><script>
const out = {};
const ws = new WebSocket("ws://CONSOLE/api/stream");
ws.onmessage = () => { out.stream = "read"; done(); };
ws.onerror = () => { out.stream = "refused"; done(); };
fetch("http://CONSOLE/api/command", {method: "POST", headers: {"Content-Type": "text/plain"},
  body: JSON.stringify({command: "service_off"})})
  .then((r) => { out.command = "status " + r.status; done(); })
  .catch(() => { out.command = "blocked"; done(); });
function done() { if (out.stream && out.command) document.title = JSON.stringify(out); }
</script></body></html>"""


def attack(url: str, foreign: str) -> dict[str, Any]:
    driver = browser()
    try:
        wait = WebDriverWait(driver, WAIT, poll_frequency=0.05)
        driver.get(url)
        alerts = driver.find_element(By.ID, "alerts")
        wait.until(lambda d: "onerror" in alerts.text)
        seen = {
            "text": alerts.text,
            "images": len(driver.find_elements(By.CSS_SELECTOR, "#alerts img, #alerts script")),
            "ran": driver.execute_script("return window.pwned === undefined ? null : window.pwned"),
            "title": driver.title,
        }
        driver.get(foreign)
        wait.until(lambda d: d.title.startswith("{"))
        seen["foreign"] = driver.title
        return seen
    finally:
        driver.quit()


def test_script_in_a_fault_is_text_and_a_foreign_page_is_refused() -> None:
    async def main() -> tuple[dict[str, Any], int, str, bool]:
        async with console_tour({"faults": [FAULT]}, once=False) as (run, _people, url):
            book = run.executive.staff.book
            await run.executive_ticks_until(lambda: "fault" in book.active)
            # the attacker's page: another loopback address, another port
            page = web.Application()
            text = FOREIGN.replace("CONSOLE", url.removeprefix("http://"))

            async def serve(_request: web.Request) -> web.Response:
                return web.Response(text=text, content_type="text/html")

            page.router.add_get("/", serve)
            runner = web.AppRunner(page)
            await runner.setup()
            site = web.TCPSite(runner, "127.0.0.2", 0)
            await site.start()
            try:
                seen = await asyncio.to_thread(attack, url, f"http://127.0.0.2:{site.port}/")
            finally:
                await runner.cleanup()
            async with aiohttp.ClientSession() as s, s.get(f"{url}/") as r:
                status, policy = r.status, r.headers["Content-Security-Policy"]
            in_service = run.executive.core.board.get(keys.IN_SERVICE) is not False
            run.executive.stop("test over")
            return seen, status, policy, in_service

    seen, status, policy, in_service = asyncio.run(main())
    assert "motors: <img src=x onerror=" in seen["text"] and "<script>" in seen["text"]
    assert seen["images"] == 0 and seen["ran"] is None and seen["title"] != "pwned"
    # the stream refused; the command refused by the console (403), or its answer hidden
    # by the browser (no CORS): either way, nothing changed (below)
    assert json.loads(seen["foreign"])["stream"] == "refused"
    assert json.loads(seen["foreign"])["command"] in ("status 403", "blocked")
    assert in_service  # the foreign page's service_off changed nothing
    assert status == 200 and "script-src 'self';" in policy and "frame-ancestors 'none'" in policy
