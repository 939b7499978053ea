"""`frog-bt demo`, the README's first command: a full tour to a docked finish, summarised."""

from __future__ import annotations

import subprocess
import sys

from mcap.reader import make_reader


def test_demo_runs_a_tour_to_a_docked_finish_and_summarises_it(tmp_path):
    mcap = tmp_path / "demo.mcap"
    result = subprocess.run(
        [sys.executable, "-m", "frog_bt", "demo", "--quiet", "--speed", "300", "--record",
         str(mcap), "--rerun", "off"], capture_output=True, text=True, timeout=120,
        cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "route:     POI0 -> POI1a -> POI2a -> POI3 -> POI4 -> POI5 -> TEMP -> END -> SHOP" in out
    assert "recruited [7]" in out
    # the engagement decision, with its sample counts, at each face-stream stop
    for about in ("introduction", "POI1", "POI2"):
        assert f"{about}: engaged: " in out and "edge samples engaged" in out
    assert "outcome:   tour ended docked" in out
    assert f"replay: frog-bt replay {mcap}" in out
    with mcap.open("rb") as f:
        assert make_reader(f).get_summary().statistics.message_count > 1000
