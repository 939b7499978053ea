"""A real Alertmanager (Debian's ``prometheus-alertmanager``, started here on a free
loopback port, no clustering) receives an alert through ``POST /api/v2/alerts``, shows it
active on ``GET /api/v2/alerts``, then resolved. Skipped, saying why, without the binary
(``.ci/run`` installs it, as it does Chromium)."""

from __future__ import annotations

import asyncio
import datetime as dt
import shutil
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from receivers import closed_port

from frog_bt.config import AlertsCfg
from frog_bt.live.console.webhooks import Webhooks
from frog_bt.runtime.alerts import AlertBook, Facts

BINARY = shutil.which("prometheus-alertmanager") or shutil.which("alertmanager")
CONSOLE = "http://127.0.0.1:8080"
CONFIG = """\
route:
  receiver: nobody
receivers:
  - name: nobody
"""
READY_WITHIN = 30.0  # wall seconds for the process to listen


@pytest.fixture
def alertmanager(tmp_path: Path) -> Iterator[str]:
    """Its base URL; the process is stopped, always, when the test ends."""
    if BINARY is None:
        pytest.skip(
            "Alertmanager is not installed: apt-get install prometheus-alertmanager "
            "(Debian; .ci/run does so)"
        )
    (tmp_path / "alertmanager.yml").write_text(CONFIG)
    port = closed_port()
    proc = subprocess.Popen(
        [
            BINARY,
            f"--config.file={tmp_path / 'alertmanager.yml'}",
            f"--storage.path={tmp_path / 'data'}",
            "--cluster.listen-address=",
            f"--web.listen-address=127.0.0.1:{port}",
            "--log.level=info",
        ],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    listening = threading.Event()
    lines: list[str] = []

    def drain() -> None:  # its log, read to the end: it says when it listens
        assert proc.stderr is not None
        for line in proc.stderr:
            lines.append(line)
            if 'msg="Listening on"' in line:
                listening.set()
        listening.set()  # it ended

    reader = threading.Thread(target=drain, daemon=True)
    reader.start()
    try:
        if not listening.wait(READY_WITHIN) or proc.poll() is not None:
            pytest.fail("Alertmanager did not start:\n" + "".join(lines[-20:]))
        yield f"http://127.0.0.1:{port}"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        reader.join(timeout=5)


async def alerts(base: str) -> list[dict[str, Any]]:
    async with aiohttp.ClientSession() as s, s.get(f"{base}/api/v2/alerts") as r:
        assert r.status == 200
        return [a for a in await r.json() if a["labels"].get("robot") == "frog"]


def test_a_real_alertmanager_shows_the_alert_active_then_resolved(alertmanager: str) -> None:
    async def main() -> tuple[list[dict[str, Any]], list[dict[str, Any]], int, int]:
        cfg = AlertsCfg.model_validate(
            {
                "webhooks": [{"url": alertmanager, "format": "alertmanager"}],
                "console_url": CONSOLE,
                "webhook_backoff": 0.05,
            }
        )
        book, hooks = AlertBook(cfg), Webhooks(cfg, ack_secret="staff-token-0123")
        book.listeners.append(hooks.notify)
        hooks.start()
        book.update(Facts(now=100.0, faults=("motors: overheated",)))
        await hooks.finish(timeout=10.0)  # returns once delivered
        active = await alerts(alertmanager)
        hooks.start()
        book.update(Facts(now=200.0))  # the fault is over
        await hooks.finish(timeout=10.0)
        resolved = await alerts(alertmanager)
        return active, resolved, hooks.stats.posted, hooks.stats.failed

    active, resolved, posted, failed = asyncio.run(main())
    assert (posted, failed) == (2, 0)
    [alert] = active
    assert alert["labels"] == {
        "alertname": "FrogRobotNeedsHelp",
        "robot": "frog",
        "kind": "fault",
        "severity": "ERROR",
    }
    assert alert["annotations"]["summary"] == (
        "The robot reports an electronics fault: motors: overheated."
    )
    assert alert["annotations"]["description"] == "Call the robot team."
    assert alert["annotations"]["ack_url"].startswith(f"{CONSOLE}/ack/fault?at=")
    assert alert["generatorURL"] == CONSOLE
    assert alert["status"]["state"] in ("active", "unprocessed")  # both: firing
    ends = dt.datetime.fromisoformat(alert["endsAt"].replace("Z", "+00:00"))
    assert ends > dt.datetime.now(dt.UTC)
    assert resolved == []  # endsAt now in the past: Alertmanager no longer lists it
