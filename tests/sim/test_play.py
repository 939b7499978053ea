"""`frog-bt sim --play`: a recorded tour served open loop drives a new `frog-bt run --once`
to the recorded tour's end; a command that differs is counted and told in replay's
terms."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.observers.recording import FRONTEND_OUT
from frog_bt.sim.play import Comparison, load
from frog_bt.tools.replay import Command

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recording"))
from recorded_tour import record_tour

FAST_ROBOT = {"navigation": {"speed": 3.0, "approach_time": 1.0},
              "docking": {"undock_time": 2.0, "dock_time": 3.0}}


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("play") / "tour.mcap"
    assert record_tour(path, FAST_ROBOT).outcome.code == 0
    return path


def _line(proc: subprocess.Popen[str], pattern: str) -> re.Match[str]:
    assert proc.stdout is not None
    for line in proc.stdout:  # bounded: the process is killed by the test's timeout
        match = re.search(pattern, line)
        if match:
            return match
    raise AssertionError(f"no line matching {pattern!r}")


def test_run_once_against_a_played_tour_reaches_its_end(recorded: Path) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        listen = probe.getsockname()[1]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    player = subprocess.Popen(
        [sys.executable, "-m", "frog_bt", "sim", "--play", str(recorded), "--speed", "60",
         "--rosbridge", "127.0.0.1:0", "--frontend", "127.0.0.1:0",
         "--executive", f"127.0.0.1:{listen}"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    try:
        ports = _line(player, r"rosbridge ws://127\.0\.0\.1:(\d+), front end udp "
                              r"127\.0\.0\.1:(\d+)")
        run = subprocess.run(
            [sys.executable, "-m", "frog_bt", "run", "--sim-time", "--once", "--quiet",
             "--checkpoint", "none", "--rosbridge", f"ws://127.0.0.1:{ports.group(1)}",
             "--frontend", f"127.0.0.1:{ports.group(2)}", "--listen", f"127.0.0.1:{listen}"],
            capture_output=True, text=True, timeout=120, env=env)
        assert run.returncode == 0, run.stderr[-2000:]
        assert "  outcome:   tour ended docked, every stop visited" in run.stdout.splitlines()
    finally:
        player.send_signal(signal.SIGINT)
        out, _ = player.communicate(timeout=15)
    assert player.returncode == 0
    final = out.strip().splitlines()[-1]
    match = re.search(r"commands: (\d+) received, (\d+) differ from the recording", final)
    assert match, final
    assert int(match.group(1)) > 50 and match.group(2) == "0", final  # the same executive


def test_a_command_that_differs_is_counted_and_told_in_domain_terms(recorded: Path) -> None:
    site = load_site()
    played = load(recorded, site)
    goals = [c for c in played.commands if c.channel == site.topic("goto")]
    assert len(goals) >= 7 and played.events and played.inputs
    comparison = Comparison(site, played.commands, start=played.start)
    ros = [c for c in played.commands if c.channel != FRONTEND_OUT]
    k = ros.index(goals[0])
    for command in ros[:k]:  # the same, up to the first goal
        assert comparison.got(command) is None
    # ... which now goes where the recording's second goal went
    assert goals[1].payload != goals[0].payload
    text = comparison.got(Command(played.start + 42.0, goals[0].channel, goals[1].payload))
    assert text is not None and text.startswith("waypoint ")
    assert comparison.received == k + 1
    assert comparison.differ == 1
    assert comparison.first.startswith("at +42.0 s: waypoint ")
    assert "1 differ from the recording" in comparison.line()


def test_a_file_that_is_no_recording_is_one_line_and_exit_2(tmp_path, capsys) -> None:
    bad = tmp_path / "notes.mcap"
    bad.write_text("hello")
    assert main(["sim", "--play", str(bad)]) == 2
    assert f"frog-bt sim: --play: {bad}: not an MCAP file" in capsys.readouterr().err


def test_with_no_client_it_plays_anyway_after_its_bound(recorded: Path) -> None:
    import asyncio

    from frog_bt.sim.play import Player

    site = load_site()
    played = load(recorded, site)

    async def main() -> tuple[int, int, int]:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as front_end_peer:
            front_end_peer.bind(("127.0.0.1", 0))
            front_end_peer.setblocking(False)
            player = Player(played, site, host="127.0.0.1", rosbridge_port=0,
                            frontend_host="127.0.0.1", frontend_port=0,
                            executive=front_end_peer.getsockname(), speed=2000.0,
                            wait_max=0.1)
            await player.start()
            try:
                await asyncio.wait_for(player.over.wait(), 30)  # a bound, not a pace
            finally:
                await player.stop()
            got = 0
            while True:
                try:
                    front_end_peer.recv(65536)
                except BlockingIOError:
                    break
                got += 1
            return player.inputs_sent, player.events_sent, got

    inputs, events, received = asyncio.run(main())
    assert inputs == len(played.inputs) and events == len(played.events) == received
