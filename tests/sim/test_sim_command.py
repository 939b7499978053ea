"""``frog-bt sim`` from the command line: help text, and roslibpy against a running sim."""

from __future__ import annotations

import json
import os
import re
import select
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from frog_bt.cli import main
from frog_bt.sim.scenario import builtin_scenarios

HERE = Path(__file__).parent


def test_help_explains_scenarios_and_speed(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["sim", "--help"])
    assert info.value.code == 0
    text = capsys.readouterr().out
    for needle in (
        "--scenario",
        "--speed",
        "speed factor",
        "extends:",
        "visitors:",
        "start_time",
        "--rosbridge",
        "--frontend",
        "--executive",
        "--log",
    ):
        assert needle in text, needle
    for name in builtin_scenarios():
        assert name in text, name


def test_a_bad_scenario_is_a_one_line_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("visitors: [{id: 1, position: [0, 0], faces: happy}]\n")
    assert main(["sim", "--scenario", str(bad)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:1:45: visitors[0].faces: expected one of engaged" in err


@pytest.mark.parametrize("flag", ["--rosbridge", "--frontend"])
def test_an_address_in_use_is_one_line_naming_the_option_and_exit_2(
    flag: str, capsys: pytest.CaptureFixture[str]
) -> None:
    kind = socket.SOCK_STREAM if flag == "--rosbridge" else socket.SOCK_DGRAM
    with socket.socket(socket.AF_INET, kind) as taken:
        taken.bind(("127.0.0.1", 0))
        if kind == socket.SOCK_STREAM:
            taken.listen()
        busy = f"127.0.0.1:{taken.getsockname()[1]}"
        other = "--frontend" if flag == "--rosbridge" else "--rosbridge"
        assert main(["sim", flag, busy, other, "127.0.0.1:0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == f"frog-bt sim: {flag} {busy}: cannot listen there: Address already in use"


def read_line(proc: subprocess.Popen[str], timeout: float) -> str:
    assert proc.stdout is not None
    ready, _, _ = select.select([proc.stdout], [], [], timeout)
    assert ready, "frog-bt sim printed nothing"
    return proc.stdout.readline()


def test_roslibpy_drives_the_robot(tmp_path: Path) -> None:
    scenario = tmp_path / "undocked.yaml"
    scenario.write_text("extends: default\nrobot: {docked: false}\n")
    with (
        socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as executive,
        open(tmp_path / "sim.log", "w") as log,
    ):
        executive.bind(("127.0.0.1", 0))  # soaks up the front end's datagrams
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "frog_bt",
                "sim",
                "--scenario",
                str(scenario),
                "--speed",
                "20",
                "--rosbridge",
                "127.0.0.1:0",
                "--frontend",
                "127.0.0.1:0",
                "--executive",
                f"127.0.0.1:{executive.getsockname()[1]}",
            ],
            stdout=subprocess.PIPE,
            stderr=log,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        try:
            banner = read_line(proc, 15)
            match = re.search(r"rosbridge ws://127\.0\.0\.1:(\d+)", banner)
            assert match, banner
            client = subprocess.run(
                [sys.executable, str(HERE / "roslibpy_client.py"), match.group(1)],
                capture_output=True,
                text=True,
                timeout=60,
            )
            result = json.loads(client.stdout.strip().splitlines()[-1])
            assert result["codes"] == [1, 2], client.stderr[-2000:]
            assert client.returncode == 0
        finally:
            proc.send_signal(signal.SIGINT)
            code = proc.wait(timeout=15)
        assert code == 0
        assert "stopped at" in (proc.stdout.read() if proc.stdout else "")


def test_the_help_example_is_a_valid_scenario(tmp_path: Path, pois: dict) -> None:
    from frog_bt.sim.command import __doc__ as doc
    from frog_bt.sim.scenario import load_scenario
    from frog_bt.sim.world import World

    lines = (doc or "").splitlines()
    start = lines.index("    extends: default")
    end = lines.index("", start)
    example = tmp_path / "example.yaml"
    example.write_text("\n".join(line[4:] for line in lines[start:end]) + "\n")
    scenario = load_scenario(example)
    assert scenario.visitors[0].wander_off is not None
    assert scenario.navigation.failures[1].poi == "POI2"
    World(scenario, pois)


def test_a_tour_through_a_relay_with_the_robot_via_it(tmp_path: Path) -> None:
    """Three commands, as a deployer would try --via: a relaying server, the robot as its
    client, and `frog-bt run --once` against the server."""
    scenario = tmp_path / "fast.yaml"
    scenario.write_text(
        "extends: default\ncontent: {default: 10, introduction: 8}\n"
        "navigation: {speed: 3.0, approach_time: 1.0}\n"
        "docking: {undock_time: 2, dock_time: 3}\n"
    )
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        listen = probe.getsockname()[1]  # the executive's front-end port, free right now
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    procs: list[subprocess.Popen[str]] = []

    def start(*argv: str) -> subprocess.Popen[str]:
        proc = subprocess.Popen(
            [sys.executable, "-m", "frog_bt", *argv],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            env=env,
        )
        procs.append(proc)
        return proc

    try:
        relay = start("sim", "--relay", "--rosbridge", "127.0.0.1:0")
        port = re.search(r"relaying rosbridge ws://127\.0\.0\.1:(\d+)", read_line(relay, 15))
        assert port, "no relay banner"
        url = f"ws://127.0.0.1:{port.group(1)}"
        robot = start(
            "sim",
            "--via",
            url,
            "--scenario",
            str(scenario),
            "--speed",
            "100",
            "--frontend",
            "127.0.0.1:0",
            "--executive",
            f"127.0.0.1:{listen}",
        )
        banner = read_line(robot, 15)
        assert f"robot via rosbridge {url}" in banner
        frontend = re.search(r"front end udp 127\.0\.0\.1:(\d+)", banner)
        assert frontend, banner
        run = subprocess.run(
            [
                sys.executable,
                "-m",
                "frog_bt",
                "run",
                "--sim-time",
                "--once",
                "--quiet",
                "--checkpoint",
                "none",
                "--rosbridge",
                url,
                "--frontend",
                f"127.0.0.1:{frontend.group(1)}",
                "--listen",
                f"127.0.0.1:{listen}",
            ],
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )
        assert run.returncode == 0, run.stderr[-2000:]
        assert "  outcome:   tour ended docked, every stop visited" in run.stdout.splitlines()
    finally:
        for proc in procs:
            proc.send_signal(signal.SIGINT)
        codes = [proc.wait(timeout=15) for proc in procs]
    assert codes == [0, 0]


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--via", "localhost:9090"], "--via 'localhost:9090': expected ws://HOST:PORT"),
        (["--via", "ws://127.0.0.1:1", "--relay"], "not allowed with argument"),
    ],
)
def test_via_mistakes_are_one_line_and_exit_2(
    argv: list[str], line: str, capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        code = main(["sim", *argv])
    except SystemExit as exc:  # argparse's own usage errors
        code = exc.code
    assert code == 2
    assert line in capsys.readouterr().err
