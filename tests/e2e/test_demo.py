"""`frog-bt demo`, the README's first command: a full tour to a docked finish, summarised."""

from __future__ import annotations

import subprocess
import sys

from mcap.reader import make_reader


def test_demo_runs_a_tour_to_a_docked_finish_and_summarises_it(tmp_path):
    mcap = tmp_path / "demo.mcap"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "frog_bt",
            "demo",
            "--quiet",
            "--speed",
            "300",
            "--record",
            str(mcap),
            "--rerun",
            "off",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "route:     POI0 -> POI1a -> POI2a -> POI3 -> POI4 -> POI5 -> TEMP -> END -> SHOP" in out
    assert "visitors:  approached 7; recruited 7" in out
    # the engagement decision, with its sample counts, at each face-stream stop
    for about in ("introduction", "POI1", "POI2"):
        assert f"{about}: engaged: " in out and "edge samples engaged" in out
    assert "outcome:   tour ended docked, every stop visited" in out
    assert "problems:" not in out
    assert f"replay: frog-bt replay {mcap}" in out
    with mcap.open("rb") as f:
        assert make_reader(f).get_summary().statistics.message_count > 1000


def test_demo_with_a_skipped_stop_says_why_and_exits_1(tmp_path):
    scenario = tmp_path / "skip.yaml"
    scenario.write_text(
        "extends: default\nnavigation:\n  failures:\n"
        "    - {poi: POI3, times: 3, result: failed, after: 5}\n"
    )
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "frog_bt",
            "demo",
            "--quiet",
            "--speed",
            "300",
            "--scenario",
            str(scenario),
            "--record",
            str(tmp_path / "d.mcap"),
            "--rerun",
            "off",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    out = result.stdout
    assert "problems:  navigation failed (3); stop skipped" in out
    assert "navigation to POI3 failed" in out
    assert "skipped POI3: navigation kept failing" in out
    assert "outcome:   tour ended docked, but POI3 skipped" in out
    assert result.stderr.strip().splitlines()[-1] == (
        "frog-bt: tour ended docked, but POI3 skipped"
    )
    assert "[" not in out.split("visitors:")[1].splitlines()[0]  # plain words, no reprs


def test_demo_pace_follows_the_console_and_the_timeout_grows_with_it():
    from frog_bt.commands.demo import pace

    assert pace(None, None, 50.0, console=True) == (2.0, 7500.0)  # a person can follow it
    assert pace(None, None, 50.0, console=False) == (50.0, 300.0)
    assert pace(300.0, None, 50.0, console=True) == (300.0, 300.0)
    assert pace(None, 20.0, 50.0, console=True) == (2.0, 20.0)  # --timeout wins


def test_demo_out_of_time_says_so_naming_timeout(tmp_path):
    result = subprocess.run(
        [
            *(sys.executable, "-m", "frog_bt", "demo", "--quiet", "--speed", "300"),
            *("--timeout", "0.5", "--record", str(tmp_path / "d.mcap"), "--rerun", "off"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert result.returncode == 1
    assert result.stderr.strip().splitlines()[-1] == (
        "frog-bt: no docked finish within 0.5 s of wall time (--timeout 0.5 at --speed 300): "
        "give a longer --timeout"
    )


def test_demo_with_console_runs_on_after_the_tour_until_ctrl_c(tmp_path):
    import json
    import re
    import signal
    import urllib.request

    proc = subprocess.Popen(
        [
            *(sys.executable, "-m", "frog_bt", "demo", "--quiet", "--speed", "300"),
            *("--console", "0", "--record", str(tmp_path / "d.mcap"), "--rerun", "off"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        assert proc.stdout is not None
        lines = []
        for line in proc.stdout:  # ends at the line below, or when the demo exits
            lines.append(line)
            if "stays open" in line:
                break
        found = re.search(r"http://127\.0\.0\.1:\d+/", lines[-1])
        assert found, "".join(lines) + proc.stderr.read()  # type: ignore[union-attr]
        with urllib.request.urlopen(found.group(0) + "api/state", timeout=10) as r:
            state = json.load(r)
        assert state["tours"]["completed"] >= 1 and state["tours"]["aborted"] == 0  # the day
        assert state["links"]["rosbridge"] == "connected"  # the robot goes on, as on a robot
        assert proc.poll() is None  # still open, after the tour
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert "outcome:   tour ended docked, every stop visited" in "".join(lines)


def test_demo_recording_into_a_missing_folder_is_one_line_not_a_traceback(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "frog_bt", "demo", "--record", "nodir/x.mcap", "--rerun", "off"],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=tmp_path,
    )
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "frog-bt: --record nodir/x.mcap: cannot write there: nodir does not exist"
    ]
