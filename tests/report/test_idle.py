"""The corpus records the robot's idle time between tours, as `frog-bt run --record DIR`
does, and the report counts it in service and says what in service counts: one short
slot of a day (20 simulated minutes, one tour in it)."""

from __future__ import annotations

import json
import sys
from datetime import datetime
from pathlib import Path

import pytest

from frog_bt.cli import main
from tests.recording.recorded_tour import FAST_TOURS

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from corpus_run import make

SLOT = ((9 * 60, 9 * 60 + 20),)  # the robot's day: 09:00 to 09:20


@pytest.fixture(scope="module")
def slot(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("idle")
    manifest = make(out, 1, 1, seed=3, jobs=1, idle=True, service=SLOT, fast=FAST_TOURS)
    return out, manifest


def test_idle_time_is_recorded_and_counted_in_service(slot, tmp_path) -> None:
    out, manifest = slot
    (tour,), (run,) = manifest["tours"], manifest["runs"]
    assert run["code"] == 0, run["reason"]
    # as --record DIR writes a day: idle before the tour, the tour, idle after it
    kinds = [name.split("-")[2][:4] for name in run["files"]]
    assert kinds == ["idle", "tour", "idle"] and tour["file"] == run["files"][1]
    opens, closes = (datetime.fromisoformat(tour[k]).timestamp() for k in ("opens", "closes"))
    assert run["service"] == [opens, closes] and closes - opens == 20 * 60
    (a, _), (_, b) = run["spans"][0], run["spans"][-1]
    assert a - opens < 5 and 0 < closes - b < 5  # the day's time, less the seams
    target, page = tmp_path / "r.json", tmp_path / "r.html"
    assert main(["report", str(out), "--json", str(target), "-o", str(page), "--quiet"]) == 0
    got = json.loads(target.read_text())
    rel, (row,) = got["totals"]["reliability"], got["tours"]
    assert rel["hours_in_service"] == pytest.approx((b - a) / 3600, abs=0.01)
    assert rel["hours_in_service"] > 0.3  # the idle time counts, not the tour's alone
    assert rel["hours_in_tours"] == pytest.approx(row["duration_s"] / 3600, abs=0.01)
    assert rel["hours_in_tours"] < rel["hours_in_service"] / 2
    # the page splits it and says what in service counts
    html = page.read_text()
    shown = html.split("<th>Hours in service</th><td>", 1)[1].split("</td>", 1)[0]
    assert shown.startswith(f"{rel['hours_in_service']:.3g} h over 1 robot-day: ")
    assert "h in tours" in shown and shown.endswith(" h idle")
    assert "idle time between them" in html
