"""``frog-bt ctl`` as a shell tool: ``--console`` as ``run`` takes it (PORT, :PORT,
HOST:PORT, a URL) or from ``FROG_BT_CONSOLE``; ``status`` in plain lines in the site's
words, ``--json`` as the console gives it; a closed pipe ends quietly."""

from __future__ import annotations

import asyncio
import json
import os
import sys
from pathlib import Path
from typing import Any

import pytest
from console_tour import console_tour
from test_faults import is_

from frog_bt.cli import main
from frog_bt.commands.ctl import console_url, state_lines
from frog_bt.errors import UsageError


@pytest.mark.parametrize(
    ("given", "url"),
    [
        ("8765", "http://127.0.0.1:8765"),
        (":8765", "http://127.0.0.1:8765"),
        ("frog-1:8080", "http://frog-1:8080"),
        ("0.0.0.0:8080", "http://127.0.0.1:8080"),  # run's listen-on-all, reached on loopback
        ("[::1]:8080", "http://[::1]:8080"),
        ("http://frog-1:8080/", "http://frog-1:8080"),
        ("https://frog-1.museum.example", "https://frog-1.museum.example"),
        (None, "http://127.0.0.1:8080"),
        ("http://frog-1:8080/api/state", "http://frog-1:8080"),  # an API's address: its console
        ("https://x.example/frog/api/command", "https://x.example/frog"),  # a proxy's prefix
        ("frog-1", "http://frog-1:8080"),  # a bare host: the console's default port
    ],
)
def test_console_addresses_as_run_takes_them(given: str | None, url: str) -> None:
    assert console_url(given) == url


def test_a_console_that_is_no_address_is_a_usage_error(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(
        UsageError, match="the console's stream, not its address: give http://frog-1:8080"
    ):
        console_url("ws://frog-1:8080/api/stream")
    with pytest.raises(UsageError, match="expected http://HOST:PORT"):
        console_url("ftp://frog-1")
    monkeypatch.setenv("FROG_BT_CONSOLE", "frog-1:http")
    assert main(["ctl", "status"]) == 2
    assert capsys.readouterr().err.startswith("frog-bt ctl: FROG_BT_CONSOLE frog-1:http:")


def test_status_in_words_in_json_from_the_environment_and_into_a_closed_pipe(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def ctl(*argv: str) -> tuple[int, str, str]:
        code = main(["ctl", *argv, "--timeout", "30"])
        printed = capsys.readouterr()
        return code, printed.out, printed.err

    async def run() -> dict[str, Any]:
        out: dict[str, Any] = {}
        async with console_tour({"speed": 20.0}, once=False) as (tour, _people, url):
            port = url.rsplit(":", 1)[1]
            await tour.sim.wait_for(is_("tour", state="started"), 60)
            out["port"] = await asyncio.to_thread(ctl, "status", "--console", port)
            out["colon"] = await asyncio.to_thread(ctl, "status", "--console", f":{port}")
            out["json"] = await asyncio.to_thread(ctl, "status", "--json", "--console", url)
            monkeypatch.setenv("FROG_BT_CONSOLE", f"127.0.0.1:{port}")
            out["env"] = await asyncio.to_thread(ctl, "status")
            out["pipe"] = await _into_a_closed_pipe(port)
        return out

    out = asyncio.run(run())
    for how in ("port", "colon", "env"):
        code, text, err = out[how]
        assert (code, err) == (0, ""), how
        lines = text.splitlines()
        assert lines[1].startswith("Parada: ")  # the site's words (config/site.yaml: es)
        assert any(line.startswith("Conexiones: El robot conectado") for line in lines)
        assert any(line.startswith("El día de hoy: Visitas empezadas 1") for line in lines)
        assert not text.lstrip().startswith("{")
    code, text, _ = out["json"]
    assert code == 0 and json.loads(text)["touring"] is True
    code, err = out["pipe"]
    assert code in (0, 141) and err == ""  # no traceback


async def _into_a_closed_pipe(port: str) -> tuple[int | None, str]:
    """``frog-bt ctl status | head -0``: the reader is gone before anything is written."""
    read, write = os.pipe()
    os.close(read)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])}
    try:
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "frog_bt",
            "ctl",
            "status",
            "--console",
            port,
            "--timeout",
            "30",
            stdout=write,
            stderr=asyncio.subprocess.PIPE,
            env=env,
        )
    finally:
        os.close(write)
    _, err = await asyncio.wait_for(proc.communicate(), 60)
    return proc.returncode, err.decode()


def test_status_lines_say_what_a_person_must_do() -> None:
    state = {
        "language": "en",
        "doing": "Waiting for a person to help",
        "stop": None,
        "touring": False,
        "battery": 22.4,
        "in_service": False,
        "paused": False,
        "help": {
            "what": "The robot could not dock after all its attempts.",
            "by_hand": "a person put the robot on its charger",
            "answers": ["retry", "done_by_hand", "service_off"],
        },
        "alerts": [{"id": "docking_failed", "state": "raised", "text": "It could not dock."}],
        "holding": [],
        "links": {"rosbridge": "connected"},
        "links_for_s": {"rosbridge": 125.0},
        "tours": {"started": 1, "completed": 0, "aborted": 0},
        "day": {"visitors": 1, "skipped": 0, "last": []},
    }
    assert state_lines(state) == [
        "Waiting for a person to help",
        "Stop: no tour now",
        "Battery: 22 %",
        "Out of service",
        "The robot is waiting for a person: The robot could not dock after all its attempts.",
        "  Done: a person put the robot on its charger",
        "  Answer with: frog-bt ctl retry | frog-bt ctl done_by_hand | frog-bt ctl service_off",
        "The robot needs help: It could not dock.",
        "  mark it seen: frog-bt ctl ack_alert docking_failed",
        "Connections: The robot connected (2 min 5 s)",
        "The day so far: Tours started 1, Completed 0, Ended early 0, Visitors 1, Stops skipped 0",
    ]
