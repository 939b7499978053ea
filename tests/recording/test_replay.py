"""`frog-bt replay`: the recorded tour replays identically; a changed tree or config diverges."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
import yaml
from mcap.writer import Writer
from recorded_tour import RecordedTour

from frog_bt.cli import main
from frog_bt.commands.replay import Progress
from frog_bt.config import DEFAULT_CONFIG, load_site
from frog_bt.tools.replay import Replay, local_time
from frog_bt.tree.loader import load_tree


def test_b_replaying_the_recorded_tour_is_identical(
        tour: RecordedTour, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(tour.path), "--quiet"]) == 0
    out = capsys.readouterr().out
    first, summary = out.splitlines()
    assert first.startswith("identical: ")
    assert "x real time" in summary and "inputs" in summary


def swapped_stops(tmp_path: Path, a: str, b: str) -> Path:
    """The site configuration with stops ``a`` and ``b`` in each other's place."""
    data = yaml.safe_load(DEFAULT_CONFIG.read_text(encoding="utf-8"))
    stops = data["tour"]["stops"]
    i, j = ([s["poi"] for s in stops].index(p) for p in (a, b))
    stops[i], stops[j] = stops[j], stops[i]
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_c_a_changed_stop_order_diverges_at_the_first_different_goal(
        tour: RecordedTour, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = swapped_stops(tmp_path, "POI4", "POI5")
    site = load_site(config)
    result = Replay(tour.path, site, load_tree(site=site)).run()
    div = result.divergence
    assert div is not None and div.expected is not None and div.got is not None
    assert div.expected.channel == div.got.channel == "/GotoWayPoint"
    assert div.expected.payload["pose"]["position"]["x"] == site.pois["POI4"].x
    assert div.got.payload["pose"]["position"]["x"] == site.pois["POI5"].x
    assert div.t == div.expected.t == div.got.t  # the same tick, with another goal

    assert main(["replay", str(tour.path), "--config", str(config), "--quiet"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == (f"divergence at {local_time(div.t)} (+{div.t - result.start:.1f} s into "
                        f"the recording), command {div.number}:")
    assert lines[1].startswith("  expected: /GotoWayPoint {") and "51.7105" in lines[1]
    assert lines[2].startswith("  got:      /GotoWayPoint {") and "52.08933" in lines[2]
    assert lines[3].startswith("replayed ")


def test_not_a_file_not_mcap_and_missing_channels_exit_2(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = tmp_path / "notes.mcap"
    text.write_text("hello\n", encoding="utf-8")
    other = tmp_path / "other.mcap"
    with open(other, "wb") as f:
        writer = Writer(f)
        writer.start()
        schema = writer.register_schema("std_msgs/String", "jsonschema", b"{}")
        channel = writer.register_channel("/chatter", "json", schema)
        writer.add_message(channel, log_time=1, data=json.dumps({"data": "hi"}).encode(),
                           publish_time=1)
        writer.finish()
    for path, reason in ((tmp_path, "not a file"), (text, "not an MCAP file"),
                         (other, "no channel /ApproachPeopleFar")):
        assert main(["replay", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and reason in err, err


def test_progress_bar_redraws_at_most_ten_times_a_second() -> None:
    out = io.StringIO()
    wall = iter([0.0, 0.05, 0.2, 0.25])
    bar = Progress(100.0, 200.0, out, wall=lambda: next(wall))
    for t in (110.0, 120.0, 150.0, 160.0):
        bar(t)
    bar.close()
    draws = out.getvalue().split("\r")[1:]
    assert len(draws) == 3  # two draws and the final erase
    assert " 10% " in draws[0] and " 50% " in draws[1] and draws[2] == "\033[K"
