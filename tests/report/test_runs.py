"""`frog-bt report` tells runs apart by their run id: different runs are all counted
whatever their times (three demos in one folder, two robots' files together), a copy of
one run's file (whole or cut) is that run read once, two runs of one robot at once are
suspicious, and files recorded before run ids keep the rule of their time."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.model.run import RUN_METADATA, read_metadata
from frog_bt.offline.report.facts import FileFacts
from frog_bt.offline.report.runs import copies, lanes, suspicious
from tests.recording.recorded_tour import record_tour

A, B = "0b8a2c1e-6f0d-4c53-9d52-1b4f1c0e9a01", "5e3f0a77-2b1c-4e8e-8f4a-6c2d9b1e7f02"


def report(tmp_path: Path, *args: str) -> dict[str, Any]:
    target = tmp_path / "out.json"
    assert main(["report", *args, "--json", str(target), "--quiet"]) == 0
    return json.loads(target.read_text())


def test_three_demos_in_one_folder_are_three_tours_with_the_faults_alert(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """All three start at the simulator's 10:30: three runs, counted, each its own row;
    one robot (frog) running three at once is suspicious, and said so."""
    folder = tmp_path / "a"
    folder.mkdir()
    for scenario, code in (("default", 0), ("fault", 1), ("declines", 0)):
        # each shipped scenario, the robot at twice its speed (the fault, 5 simulated
        # minutes in, still strikes mid-tour)
        faster = tmp_path / f"{scenario}.yaml"
        faster.write_text(f"extends: {scenario}\nnavigation:\n  speed: 1.2\n")
        args = ["--scenario", str(faster), "--record", str(folder / f"{scenario}.mcap")]
        assert main(["demo", *args, "--speed", "400", "--rerun", "off", "--quiet"]) == code
    capsys.readouterr()
    got = report(tmp_path, str(folder))
    by_file = {tuple(r["files"]): r for r in got["tours"]}
    assert sorted(by_file) == [("declines.mcap",), ("default.mcap",), ("fault.mcap",)]
    assert got["totals"]["tours"] == 3
    fault = by_file["fault.mcap",]
    assert fault["ended"] == "aborted" and [a["kind"] for a in fault["alerts"]] == ["fault"]
    assert by_file["declines.mcap",]["invitations_declined"] == 1
    assert [r["alerts"] for f, r in by_file.items() if f != ("fault.mcap",)] == [[], []]
    prov = got["totals"]["provenance"]
    assert prov["skipped"] == [] and prov["runs"] == 3 and prov["without_run_id"] == 0
    assert len(prov["suspicious"]) == 2
    assert all("another run of robot frog" in s for s in prov["suspicious"])
    assert "suspicious: " in capsys.readouterr().err


def test_two_robots_files_in_one_folder_are_both_counted(tmp_path: Path) -> None:
    """Two robots' tours at the same hours, their files in one folder: two runs, both
    read, and nothing suspicious (two robots, by their configured names)."""
    folder = tmp_path / "fleet"
    folder.mkdir()
    site = load_site()
    for robot in ("frog1", "frog2"):
        named = site.model_copy(update={"alerts": site.alerts.model_copy(update={"robot": robot})})
        tour = record_tour(folder / f"{robot}.mcap", site=named)
        assert tour.outcome.code == 0, tour.outcome.reason
    got = report(tmp_path, str(folder))
    assert sorted(r["files"] for r in got["tours"]) == [["frog1.mcap"], ["frog2.mcap"]]
    assert all(r["ended"] == "ended" for r in got["tours"])
    prov = got["totals"]["provenance"]
    assert prov["runs"] == 2 and prov["skipped"] == [] and prov["suspicious"] == []


def facts(file: str, start: float, end: float, run: str = "", robot: str = "") -> FileFacts:
    return FileFacts(file, start=start, end=end, run=run, robot_name=robot)


def test_one_run_overlapping_itself_is_a_copy_and_runs_apart_are_not() -> None:
    files = [
        facts("d/1.mcap", 0, 100, A, "frog"),
        facts("d/2.mcap", 99.5, 200, A, "frog"),  # rotated: a seam, no copy
        facts("d/copy.mcap", 10, 60, A, "frog"),  # one run's file, cut, put beside it
        facts("d/other.mcap", 5, 150, B, "frog"),  # another run at the same hours
    ]
    got = copies(files)
    assert list(got) == ["d/copy.mcap"]
    assert got["d/copy.mcap"].startswith("the same run as 1.mcap (run 0b8a2c1e) and overlaps")
    assert sorted(lanes(files)) == [f"run {A}", f"run {B}"]


def test_files_recorded_before_run_ids_keep_the_rule_of_their_time_and_say_so() -> None:
    files = [
        facts("d/old.mcap", 0, 100),
        facts("d/old-copy.mcap", 20, 80),
        facts("e/old.mcap", 20, 80),  # another directory: another robot
        facts("d/new.mcap", 20, 80, A, "frog"),  # a run id: its own run
    ]
    got = copies(files)
    assert list(got) == ["d/old-copy.mcap"]
    assert got["d/old-copy.mcap"] == (
        "overlaps old.mcap in time, which one robot's recordings cannot: a copy? "
        "(no run id, recorded before run ids: the longer one is read)"
    )
    assert sorted(lanes(files)) == ["d", "e", f"run {A}"]
    assert suspicious(files) == []  # no robot name to go by


def test_runs_of_one_robot_at_once_are_suspicious_and_of_two_robots_not() -> None:
    files = [
        facts("d/a.mcap", 0, 100, A, "frog"),
        facts("d/b.mcap", 50, 150, B, "frog"),
        facts("d/c.mcap", 149.5, 300, A, "frog"),  # a seam's overlap with b: not
        facts("e/x.mcap", 0, 300, "6a1b2c3d-4e5f-4a6b-8c7d-9e0f1a2b3c04", "frog2"),
    ]
    assert suspicious(files) == [
        "d/b.mcap: overlaps a.mcap in time, a file of another run of robot frog: two "
        "executives of one robot at once? (both are counted)"
    ]


def test_a_files_run_is_believed_only_when_it_fits() -> None:
    """The metadata comes from a file: an id that is no UUID, or a robot name the site
    configuration would refuse (terminal escapes), is read as not recorded."""
    good = read_metadata({RUN_METADATA: {"id": A, "robot": "frog-2", "resumes": A}})
    assert (good.id, good.robot, good.resumes) == (A, "frog-2", A)
    bad = read_metadata({RUN_METADATA: {"id": A.replace("-", ""), "robot": "\x1b[2Jfrog"}})
    assert (bad.id, bad.robot, bad.resumes) == ("", "", "")
    assert read_metadata({}) == read_metadata({"frog_bt_site": {"config_sha256": "x"}})
