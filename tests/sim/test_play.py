"""`frog-bt sim --play`: a recorded tour served open loop drives a new `frog-bt run --once`
to the recorded tour's end (a whole single-file recording, and a tour file of `--record
DIR` after its lead-in); a command that differs is counted and told in replay's terms;
`--loop` plays again later; files it cannot play are one line and exit 2."""

from __future__ import annotations

import asyncio
import itertools
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer
from sim_clients import RosClient

from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.model import channels
from frog_bt.model.channels import FRONTEND_OUT
from frog_bt.recordings.commands import Command
from frog_bt.recordings.mcapfile import open_recording
from frog_bt.sim.comparison import Comparison
from frog_bt.sim.play import DT, PASS_TAIL, Player, load, restamped

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recording"))
from recorded_tour import record_day, record_tour

FAST_ROBOT = {
    "navigation": {"speed": 3.0, "approach_time": 1.0},
    "docking": {"undock_time": 2.0, "dock_time": 3.0},
}
HOST = "127.0.0.1"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One whole tour in one file (as `frog-bt demo --record FILE` writes)."""
    path = tmp_path_factory.mktemp("play") / "tour.mcap"
    assert record_tour(path, FAST_ROBOT).outcome.code == 0
    return path


@pytest.fixture(scope="module")
def day(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Two tours recorded as `--record DIR` does: idle1, tour1, idle2, tour2, idle3."""
    files = record_day(tmp_path_factory.mktemp("play") / "day", 2, 10**12).files
    assert [f.name[16:20] for f in files] == ["idle", "tour", "idle", "tour", "idle"]
    return files


def _line(proc: subprocess.Popen[str], pattern: str) -> re.Match[str]:
    assert proc.stdout is not None
    for line in proc.stdout:  # bounded: the process is killed by the test's timeout
        match = re.search(pattern, line)
        if match:
            return match
    raise AssertionError(f"no line matching {pattern!r}")


def _free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind((HOST, 0))
        return probe.getsockname()[1]


@pytest.mark.parametrize("which", ["one file", "tour file of a day"])
def test_run_once_against_a_played_tour_reaches_its_end(
    which: str, request: pytest.FixtureRequest
) -> None:
    if which == "one file":
        path, played = request.getfixturevalue("recorded"), ["tour.mcap"]
    else:
        files = request.getfixturevalue("day")
        path, played = files[3], [files[2].name, files[3].name]  # tour 2 after its lead-in
    listen = _free_udp_port()
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    player = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "frog_bt",
            "sim",
            "--play",
            str(path),
            "--speed",
            "60",
            "--rosbridge",
            f"{HOST}:0",
            "--frontend",
            f"{HOST}:0",
            "--executive",
            f"{HOST}:{listen}",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env=env,
    )
    try:
        start = _line(
            player,
            r"playing (.*) \(\d+ inputs.* rosbridge ws://127\.0\.0\.1:(\d+), "
            r"front end udp 127\.0\.0\.1:(\d+)",
        )
        assert [Path(f).name for f in start.group(1).split(", ")] == played
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
                f"ws://{HOST}:{start.group(2)}",
                "--frontend",
                f"{HOST}:{start.group(3)}",
                "--listen",
                f"{HOST}:{listen}",
            ],
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )
        assert run.returncode == 0, run.stderr[-2000:]
        assert "  outcome:   tour ended docked, every stop visited" in run.stdout.splitlines()
    finally:
        player.send_signal(signal.SIGINT)
        out, _ = player.communicate(timeout=15)
    assert player.returncode == 0
    final = out.strip().splitlines()[-1]
    match = re.search(
        r"stopped; played (\d+) inputs and (\d+) front-end events; "
        r"commands: (\d+) received, (\d+) differ from the recording",
        final,
    )
    assert match, final
    inputs, events, received, differ = map(int, match.groups())
    assert inputs > 500 and events >= 5, final
    assert received > 50 and differ == 0, final  # the same executive: the same commands


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


def test_a_day_file_is_played_after_its_lead_in_and_from_its_primer(day: list[Path]) -> None:
    """A tour file after the idle file it continues; an idle file's primer (the latest
    input of each topic from before it) first, at its start."""
    site = load_site()
    tour = load(day[3], site)
    assert tour.files == [str(day[2]), str(day[3])]
    assert tour.commands and tour.events
    idle = load(day[2], site)
    primer = next(
        channels.decode(topic, bytes(data))
        for topic, _, data in open_recording(day[2]).messages()
        if topic == channels.PRIMER
    )
    assert primer.inputs
    first = [(topic, msg) for t, topic, msg in idle.inputs if t == idle.start]
    assert first == [(p.topic, json.loads(bytes(p.msg))) for p in primer.inputs]
    assert ("/docking/state", {"data": "docked"}) in first
    assert tour.inputs[: len(first)] == idle.inputs[: len(first)]


def test_loop_plays_again_later_with_the_clock_and_stamps_going_forward(recorded: Path) -> None:
    """With --loop the second pass runs on after the first (the clock never goes back),
        its stamps moved with it, its front-end events numbered after the first pass's (the
    front-end protocol's datagrams, seq from 1 over the whole play)."""
    site = load_site()
    played = load(recorded, site)
    pose = site.topic("pose")
    length = played.end - played.start + PASS_TAIL + DT
    second = played.start + length  # where the second pass starts

    async def play() -> tuple[list[float], list[tuple[float, float]], list[Any], Player]:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as executive:
            executive.bind((HOST, 0))
            executive.setblocking(False)
            player = Player(
                played,
                site,
                host=HOST,
                rosbridge_port=0,
                frontend_host=HOST,
                frontend_port=0,
                executive=executive.getsockname(),
                speed=2000.0,
                loop=True,
            )
            await player.start()
            clocks: list[float] = []
            poses: list[tuple[float, float]] = []  # (the clock then, the pose's stamp)
            try:
                client = await RosClient.open(player.rosbridge.port)
                await client.subscribe("/clock")
                await client.subscribe(pose)
                async with asyncio.timeout(30):  # a bound, not a pace
                    while not clocks or clocks[-1] < second + length:  # two whole passes
                        frame = await client.next(lambda f: f.get("op") == "publish")
                        if frame["topic"] == "/clock":
                            c = frame["msg"]["clock"]
                            clocks.append(c["secs"] + c["nsecs"] / 1e9)
                        elif clocks:
                            s = frame["msg"]["header"]["stamp"]
                            poses.append((clocks[-1], s["secs"] + s["nsecs"] / 1e9))
                await client.close()
            finally:
                await player.stop()
            datagrams = []
            while True:
                try:
                    datagrams.append(json.loads(executive.recv(65536)))
                except BlockingIOError:
                    break
            return clocks, poses, datagrams, player

    clocks, poses, datagrams, player = asyncio.run(play())
    assert all(b > a for a, b in itertools.pairwise(clocks))
    assert clocks[0] == pytest.approx(played.start) and player.passes >= 2
    assert any(clock > second for clock, _ in poses)
    assert all(clock - 1.0 <= stamp <= clock + 1e-6 for clock, stamp in poses)
    n = len(played.events)
    assert [d["seq"] for d in datagrams[: 2 * n]] == list(range(1, 2 * n + 1))  # numbered on
    assert [d["type"] for d in datagrams[: 2 * n]] == [m.type for _, m in played.events] * 2
    recorded_not_meter = sum(c.payload.get("type") != "engagement" for c in played.commands)
    assert player.comparison.missed >= recorded_not_meter  # no executive: none received


def test_restamped_moves_a_header_stamp_in_its_own_shape() -> None:
    ros1 = {"header": {"stamp": {"secs": 10, "nsecs": 900_000_000}, "frame_id": "map"}}
    assert restamped(ros1, 0.25) == {
        "header": {"stamp": {"secs": 11, "nsecs": 150_000_000}, "frame_id": "map"}
    }
    ros2 = {"header": {"stamp": {"sec": 10, "nanosec": 0}}, "data": 1}
    assert restamped(ros2, 2.0) == {"header": {"stamp": {"sec": 12, "nanosec": 0}}, "data": 1}
    assert restamped({"data": "docked"}, 5.0) == {"data": "docked"}
    assert restamped(ros1, 0.0) is ros1


def test_with_no_client_it_plays_anyway_after_its_bound(recorded: Path) -> None:
    site = load_site()
    played = load(recorded, site)

    async def play() -> tuple[int, int, int]:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as front_end_peer:
            front_end_peer.bind((HOST, 0))
            front_end_peer.setblocking(False)
            player = Player(
                played,
                site,
                host=HOST,
                rosbridge_port=0,
                frontend_host=HOST,
                frontend_port=0,
                executive=front_end_peer.getsockname(),
                speed=2000.0,
                wait_max=0.1,
            )
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

    inputs, events, received = asyncio.run(play())
    assert inputs == len(played.inputs) and events == len(played.events) == received


def _foreign(path: Path) -> Path:
    """A valid MCAP file with nothing of the robot in it."""
    with open(path, "wb") as f:
        writer = Writer(f)
        writer.start()
        schema = writer.register_schema("std_msgs/String", "jsonschema", b"{}")
        channel = writer.register_channel("/chatter", "json", schema)
        writer.add_message(channel, log_time=1, data=b'{"data": "hi"}', publish_time=1)
        writer.finish()
    return path


def test_files_it_cannot_play_are_one_line_and_exit_2(
    tmp_path: Path, day: list[Path], capsys: pytest.CaptureFixture[str]
) -> None:
    text = tmp_path / "notes.mcap"
    text.write_text("hello")
    alone = tmp_path / day[3].name  # a tour file without the idle file it continues
    shutil.copy(day[3], alone)
    for path, reason in (
        (text, f"{text}: not an MCAP file"),
        (_foreign(tmp_path / "chatter.mcap"), "no robot-side inputs in it"),
        (alone, f"continues {day[2].name}, which is gone"),
        (tmp_path / "nowhere.mcap", "nowhere.mcap"),
    ):
        assert main(["sim", "--play", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("frog-bt sim: --play: ") and err.count("\n") == 1, err
        assert reason in err, err


def test_loop_without_play_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["sim", "--loop"]) == 2
    assert capsys.readouterr().err == "frog-bt sim: --loop goes with --play FILE.mcap\n"
