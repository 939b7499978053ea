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
