"""`frog-bt run` as outside tools drive it (CONTRACT §5): a subprocess against the simulator."""

from __future__ import annotations

import asyncio
import contextlib
import os
import signal
import socket
import subprocess
import sys

import pytest
from tour import fast, free_udp_port

from frog_bt.config import DEFAULT_CONFIG as CONFIG
from frog_bt.runtime.checkpoint import claim
from frog_bt.sim import Simulator


@contextlib.contextmanager
def checkpoint_claim(path):
    handle = claim(path)
    try:
        yield handle
    finally:
        handle.close()


async def _run_once(*python: str) -> tuple[int, bytes, list[str], str]:
    scenario = fast({"speed": 400.0})  # not paced by the executive (another process)
    listen = free_udp_port()
    sim = Simulator(scenario, rosbridge_port=0, frontend_port=0, executive=("127.0.0.1", listen))
    await sim.start()
    try:
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            *python,
            "-m",
            "frog_bt",
            "run",
            "--sim-time",
            "--once",
            "--quiet",
            "--checkpoint",
            "none",
            "--rosbridge",
            f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend",
            f"127.0.0.1:{sim.frontend_port}",
            "--listen",
            f"127.0.0.1:{listen}",
            stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE,
        )
        stdout, stderr = await asyncio.wait_for(proc.communicate(), 90)
        tours = [r.payload["state"] for r in sim.received("tour")]
        return proc.returncode or 0, stderr, tours, stdout.decode()
    finally:
        await sim.stop()


def test_run_once_exits_0_after_one_tour_ends_docked():
    code, stderr, tours, stdout = asyncio.run(_run_once())
    assert code == 0, stderr.decode()
    assert tours == ["started", "ended"]
    banner = stdout.splitlines()[:3]
    assert banner[0].startswith("frog-bt 0.1.0: tree ") and "tour.yaml, config " in banner[0]
    assert banner[1].startswith("  clock sim time (/clock); rosbridge ws://127.0.0.1:")
    assert banner[2] == "  checkpoint off; recording off; telemetry off"
    assert "  outcome:   tour ended docked, every stop visited" in stdout.splitlines()


def test_a_tour_with_face_data_never_imports_numpy_in_the_executive():
    # numpy imported mid-tour, at a moment the process is out of descriptors, is left
    # half-initialised for good ("cannot load module more than once per process"): the
    # face stream then failed every tick and the tour stood still. The executive's
    # process does without it; -X importtime lists every import the process made.
    code, stderr, tours, stdout = asyncio.run(_run_once("-X", "importtime"))
    assert code == 0 and tours == ["started", "ended"], stderr.decode()[-2000:]
    assert "engaged?   introduction: engaged: " in stdout  # the face stream was used
    imported = [line.rsplit("|", 1)[-1].strip() for line in stderr.decode().splitlines()]
    assert "frog_bt.maths.engagement" in imported
    assert not [name for name in imported if name.split(".")[0] == "numpy"]


def test_bad_config_is_one_line_and_exit_2(tmp_path):
    bad = tmp_path / "site.yaml"
    bad.write_text("pois: {}\ntour: {stops: [{poi: POI1}]}\n")
    result = subprocess.run(
        [sys.executable, "-m", "frog_bt", "run", "--config", str(bad)],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        # tour.dock is not in the file: the line is its nearest ancestor's, tour
        f"frog-bt: {bad}:2:7: tour.dock: unknown POI 'SHOP' (no POIs are defined)"
    ]


def _run(*argv: str, cwd=None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "frog_bt", "run", "--quiet", "--once", *argv],
        capture_output=True,
        text=True,
        timeout=30,
        cwd=cwd,
    )


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (
            ["--rosbridge", "127.0.0.1:9090"],
            "--rosbridge 127.0.0.1:9090: expected ws://HOST:PORT, e.g. ws://127.0.0.1:9090",
        ),
        (
            ["--rosbridge", "http://127.0.0.1:9090"],
            "--rosbridge http://127.0.0.1:9090: expected ws://HOST:PORT, e.g. ws://127.0.0.1:9090 "
            "(not http://)",
        ),
        (
            ["--rosbridge", "ws://127.0.0.1:90900"],
            "--rosbridge ws://127.0.0.1:90900: expected ws://HOST:PORT, e.g. ws://127.0.0.1:9090 "
            "(Port out of range 0-65535)",
        ),
        (
            ["--frontend", "127.0.0.1"],
            "--frontend 127.0.0.1: expected HOST:PORT (e.g. 127.0.0.1:5005)",
        ),
        (
            ["--listen", "127.0.0.1:http"],
            "--listen 127.0.0.1:http: expected HOST:PORT with a port from 0 to 65535, "
            "got port 'http'",
        ),
        (
            ["--listen", "no-such-host.invalid:5006"],
            "--listen no-such-host.invalid:5006: cannot listen there: ",
        ),
        (
            ["--frontend", "no-such-host.invalid:5005"],
            "--frontend no-such-host.invalid:5005: cannot resolve the host: ",
        ),
        (
            ["--checkpoint", "/dev/null/checkpoint.json"],
            "--checkpoint /dev/null/checkpoint.json: cannot write there: "
            "/dev/null is not a directory",
        ),
        (
            ["--record", "/no/such/dir/tour.mcap"],
            "--record /no/such/dir/tour.mcap: cannot write there: /no/such/dir does not exist",
        ),
        (
            ["--rerun", "save:/no/such/dir/t.rrd"],
            "--rerun save:/no/such/dir/t.rrd: cannot write there: /no/such/dir does not exist",
        ),
        (
            ["--rerun", "bogus"],
            "--rerun bogus: expected spawn, save:FILE.rrd, connect[:URL], serve or off",
        ),
        (  # empty is a value given, not the site's default
            ["--rosbridge", ""],
            "--rosbridge: expected ws://HOST:PORT, e.g. ws://127.0.0.1:9090",
        ),
        (["--listen", ""], "--listen: expected HOST:PORT"),
        (
            ["--config", "/no/such/site.yaml"],
            "/no/such/site.yaml: cannot read: No such file or directory",
        ),
        (
            ["--tree", "/no/such/tour.yaml"],
            "/no/such/tour.yaml: cannot read: No such file or directory",
        ),
    ],
)
def test_user_errors_are_one_line_naming_the_option_and_exit_2(tmp_path, argv, line):
    # no free port is needed: each error is found before anything connects or binds,
    # except the listen/frontend host ones, which fail resolving a name that cannot exist
    if "--checkpoint" not in argv:
        argv = ["--checkpoint", "none", *argv]
    result = _run(*argv, cwd=tmp_path)
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and lines[0].startswith(f"frog-bt: {line}"), result.stderr
    assert "Traceback" not in result.stdout + result.stderr


def test_a_listen_port_in_use_is_one_line_and_exit_2(tmp_path):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        result = _run("--checkpoint", "none", "--listen", f"127.0.0.1:{port}", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"frog-bt: --listen 127.0.0.1:{port}: cannot listen there: Address already in use "
        "(is another frog-bt or front end using it?)"
    ]


def test_a_bad_rosbridge_url_in_the_site_config_names_its_path(tmp_path):
    site = tmp_path / "site.yaml"
    site.write_text(
        CONFIG.read_text().replace("rosbridge: ws://127.0.0.1:9090", "rosbridge: 127.0.0.1:9090")
    )
    result = _run("--config", str(site), "--checkpoint", "none", cwd=tmp_path)
    assert result.returncode == 2
    line = next(
        i
        for i, text in enumerate(site.read_text().splitlines(), 1)
        if "rosbridge: 127.0.0.1:9090" in text
    )
    assert result.stderr.strip().splitlines() == [
        f"frog-bt: {site}:{line}:14: links.rosbridge: expected ws://HOST:PORT, "
        "e.g. ws://127.0.0.1:9090"
    ]


def test_two_executives_never_share_a_checkpoint(tmp_path):
    checkpoint = tmp_path / "cp.json"
    with checkpoint_claim(checkpoint):
        result = _run("--checkpoint", str(checkpoint), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"frog-bt: --checkpoint {checkpoint}: in use by another running executive "
        f"(pid {os.getpid()}); give each executive its own --checkpoint"
    ]


def test_status_line_says_rosbridge_is_unreachable_and_sigint_exits_0(tmp_path):
    port = free_udp_port()  # nothing listens on this TCP port either
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "frog_bt",
            "run",
            "--checkpoint",
            "none",
            "--rosbridge",
            f"ws://127.0.0.1:{port}",
            "--listen",
            f"127.0.0.1:{free_udp_port()}",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        assert proc.stderr is not None
        seen = []
        for line in proc.stderr:
            seen.append(line)
            if "(2+ attempts)" in line:
                break
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=10)
    finally:
        proc.kill()
    status = [s for s in seen if s.startswith("rosbridge:")]
    # not a terminal: states, not a countdown (a journal would fill up otherwise)
    assert status and status[-1].rstrip() == (
        f"rosbridge: connecting to ws://127.0.0.1:{port} (2+ attempts): connection refused"
    )
    assert not any("next in" in s for s in status)
    assert not any("Wait for the front end" in s for s in seen)
    assert proc.returncode == 0
