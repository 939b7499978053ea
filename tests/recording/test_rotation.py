"""`frog-bt run --record DIR`: one file per tour and idle period, a disk budget, a killed writer."""

from __future__ import annotations

import asyncio
import json
import logging
import os
import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from recorded_tour import FAST_TOURS, record_day

from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.live.rotation import RecordingDir, numbered
from frog_bt.offline.replay import Replay
from frog_bt.recordings.commands import ReplayError
from frog_bt.rehearsal import free_udp_port
from frog_bt.sim import Simulator, scenario_from

ROOT = Path(__file__).resolve().parents[2]


def metadata(path: Path) -> dict[str, str]:
    with open(path, "rb") as f:
        reader = make_reader(f)
        assert reader.get_summary() is not None  # closed: summary and footer written
        return {
            k: v
            for m in reader.iter_metadata()
            if m.name == "frog_bt"
            for k, v in m.metadata.items()
        }


def test_a_day_is_recorded_one_file_per_tour_and_idle_period_each_replaying_alone(
    tmp_path: Path,
) -> None:
    """Two tours: idle 1, tour 1, idle 2, tour 2, idle 3 (stopped there), named by the
    clock's local time and number, each closed with a footer; every file replays
    identically on its own (a tour file after its lead-in, an idle file from its primer)."""
    recordings = record_day(tmp_path / "day", 2, 10**12)
    names = [p.name for p in recordings.files]
    assert [n[16:] for n in names] == [
        "idle0001.mcap",
        "tour0001.mcap",
        "idle0002.mcap",
        "tour0002.mcap",
        "idle0003.mcap",
    ]
    assert all(n.startswith("20260601-10") for n in names)  # the scenario's day, not today
    assert [p for _, p in numbered(tmp_path / "day")] == recordings.files
    assert metadata(recordings.files[1]) == {"kind": "tour", "tour": "1", "lead_in": names[0]}
    assert metadata(recordings.files[2]) == {"kind": "idle", "tour": "2"}
    site = load_site()
    for path in recordings.files:
        result = Replay(path, site, load_tree(site=site)).run()
        assert result.divergence is None, (path.name, result.divergence)
        assert not result.recovered
    tour = Replay(recordings.files[3], site, load_tree(site=site)).run()
    assert tour.ros_commands >= 10 and tour.frontend_commands >= 20  # a whole tour in it


def test_the_budget_deletes_the_oldest_tours_first_and_logs_each(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    day = tmp_path / "day"
    day.mkdir()
    for name, size in (
        ("20260601-090000-idle0001", 100),
        ("20260601-090100-tour0001", 400),
        ("20260601-100000-idle0002", 100),
        ("20260601-100100-tour0002", 400),
        ("20260601-110000-idle0003", 100),
    ):
        (day / f"{name}.mcap").write_bytes(b"x" * size)
    (day / "notes.mcap").write_bytes(b"x" * 5000)  # not ours: never counted nor deleted
    recordings = RecordingDir(day, 700)
    assert recordings.number == 4  # numbers go on after the highest in DIR
    with caplog.at_level(logging.WARNING, logger="frog_bt.live.rotation"):
        recordings.enforce_budget()
    assert sorted(p.name for p in day.iterdir()) == [
        "20260601-100000-idle0002.mcap",
        "20260601-100100-tour0002.mcap",
        "20260601-110000-idle0003.mcap",
        "notes.mcap",
    ]
    assert [r.getMessage() for r in caplog.records] == [
        "recording budget 700 bytes: deleted 20260601-090000-idle0001.mcap (100 bytes)",
        "recording budget 700 bytes: deleted 20260601-090100-tour0001.mcap (400 bytes)",
    ]


def test_a_small_budget_keeps_the_latest_tours_while_recording(tmp_path: Path) -> None:
    recordings = record_day(tmp_path / "day", 3, 400_000)
    left = [p.name[16:] for _, p in numbered(tmp_path / "day")]
    assert recordings.deleted and left[-1] == "idle0004.mcap"
    assert "idle0001.mcap" not in left and "tour0001.mcap" not in left
    # the budget holds at each rotation; the file written since (the last) grows past it
    *closed, _writing = (p for _, p in numbered(tmp_path / "day"))
    assert sum(p.stat().st_size for p in closed) <= 400_000


def test_a_tour_without_its_lead_in_says_why_it_cannot_be_replayed(tmp_path: Path) -> None:
    recordings = record_day(tmp_path / "day", 1, 10**12)
    recordings.files[0].unlink()
    site = load_site()
    with pytest.raises(ReplayError, match=r"continues .*idle0001.mcap, which is gone"):
        Replay(recordings.files[1], site, load_tree(site=site))


def test_a_killed_writers_file_is_recovered_by_replay_and_numbering_goes_on(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`frog-bt run --record DIR` killed with SIGKILL in the middle of a tour: the tour
    file has no footer; replay says it recovered it, and what is there replays
    identically. A restarted executive goes on with the next number."""
    day = tmp_path / "day"

    async def run_and_kill() -> None:
        listen = free_udp_port()
        sim = Simulator(
            scenario_from("default", {**FAST_TOURS, "speed": 50.0}),
            rosbridge_port=0,
            frontend_port=0,
            executive=("127.0.0.1", listen),
        )
        await sim.start()
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "frog_bt",
            "run",
            "--sim-time",
            "--checkpoint",
            "none",
            "--record",
            str(day),
            "--quiet",
            "--rosbridge",
            f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend",
            f"127.0.0.1:{sim.frontend_port}",
            "--listen",
            f"127.0.0.1:{listen}",
            cwd=ROOT,
            stdout=asyncio.subprocess.DEVNULL,
            stderr=asyncio.subprocess.DEVNULL,
        )
        try:
            # In the tour (its file is open) and past a chunk flush (a second of wall time
            # at most after the fourth goal): then kill, without warning.
            goals = [0]

            def fourth_goal(record: Any) -> bool:
                goals[0] += record.channel == "/GotoWayPoint"
                return goals[0] >= 4

            await sim.wait_for(fourth_goal, timeout=60)
            # The file system cannot be waited on: poll it, bounded, and fail loudly when
            # the tour file never grows past its first flushed chunks.
            deadline = asyncio.get_running_loop().time() + 60.0
            while True:
                tours = [p for _, p in numbered(day) if "-tour" in p.name]
                if tours and tours[-1].stat().st_size > 50_000:
                    break
                assert asyncio.get_running_loop().time() < deadline, (
                    f"no tour file past 50 kB within 60 s: {[p.name for p in tours]}"
                )
                await asyncio.sleep(0.05)
            os.kill(proc.pid, signal.SIGKILL)
            await proc.wait()
        finally:
            if proc.returncode is None:
                proc.kill()
                await proc.wait()
            await sim.stop()

    asyncio.run(run_and_kill())
    files = [p for _, p in numbered(day)]
    assert [p.name[16:] for p in files] == ["idle0001.mcap", "tour0001.mcap"]
    assert main(["replay", str(files[1]), "--quiet"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(
        f"note: {files[1].name}: cut short (no summary or footer): recovered "
    ) and out[0].endswith("; replayed up to the cut")
    assert out[1].startswith("identical: ")
    assert main(["replay", str(day), "--quiet", "--report", str(tmp_path / "r.json")]) == 0
    rows = json.loads((tmp_path / "r.json").read_text())["tours"]
    assert [r["status"] for r in rows] == ["identical", "identical"]
    assert rows[1]["recovered"].startswith(f"{files[1].name}: cut short")
    assert RecordingDir(day, 10**12).number == 2  # a restart goes on with tour 2
