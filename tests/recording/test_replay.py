"""`frog-bt replay`: the recorded tour replays identically; a changed tree or config diverges."""

from __future__ import annotations

import io
import json
import re
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.writer import Writer
from recorded_tour import RecordedTour, record_tour

from frog_bt import resources
from frog_bt.behaviours import FACTORY, load_tree
from frog_bt.cli import main
from frog_bt.commands.replay import Progress
from frog_bt.config import DEFAULT_CONFIG, load_site
from frog_bt.offline.replay import Replay
from frog_bt.recordings.commands import differences, local_time


def test_b_replaying_the_recorded_tour_is_identical(
    tour: RecordedTour, capsys: pytest.CaptureFixture[str]
) -> None:
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
    tour: RecordedTour, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
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
    assert lines[0] == (
        f"divergence at {local_time(div.t)} (+{div.t - result.start:.1f} s into "
        f"the recording), command {div.number}:"
    )
    assert lines[1].startswith("  expected: /GotoWayPoint {") and "51.7105" in lines[1]
    assert lines[2].startswith("  got:      /GotoWayPoint {") and "52.08933" in lines[2]
    assert lines[3] == "  differs:  waypoint POI4 → POI5"  # in domain terms
    sent = [line for line in lines if " sent by " in line]
    assert sent[0].startswith("  recorded: sent by Navigate POI4 (goto.yaml:")
    assert sent[1].startswith("  replayed: sent by Navigate POI5 (goto.yaml:")
    assert div.expected.node.startswith("Navigate POI4") and div.got.node.startswith(
        "Navigate POI5"
    )  # blame: the node that sent each command, on both sides
    assert lines[-1].startswith("replayed ")


def test_not_a_file_not_mcap_and_missing_channels_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = tmp_path / "notes.mcap"
    text.write_text("hello\n", encoding="utf-8")
    other = tmp_path / "other.mcap"
    with open(other, "wb") as f:
        writer = Writer(f)
        writer.start()
        schema = writer.register_schema("std_msgs/String", "jsonschema", b"{}")
        channel = writer.register_channel("/chatter", "json", schema)
        writer.add_message(
            channel, log_time=1, data=json.dumps({"data": "hi"}).encode(), publish_time=1
        )
        writer.finish()
    empty = tmp_path / "empty"
    empty.mkdir()
    for path, reason in (
        (empty, "no recordings (*.mcap) found"),
        (text, "not an MCAP file"),
        (other, "no channel /ApproachPeopleFar"),
    ):
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


def changed_config(tmp_path: Path, change: Any) -> Path:
    data = yaml.safe_load(DEFAULT_CONFIG.read_text(encoding="utf-8"))
    change(data)
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_a_moved_variant_cut_off_is_blamed_on_the_variant_choice(
    tour: RecordedTour, tmp_path: Path
) -> None:
    """The tour was recorded at 10:30; with POI1's variant a only until 10:00 the replay
    drives to POI1b: the report says so in waypoint names, and which node sent each."""
    config = changed_config(tmp_path, lambda d: d["variants"]["POI1"][0].update(until="10:00"))
    site = load_site(config)
    div = Replay(tour.path, site, load_tree(site=site)).run().divergence
    assert div is not None
    assert differences(div.expected, div.got, site) == "waypoint POI1a → POI1b"
    assert div.expected.node.startswith("Navigate POI1 (goto.yaml:")
    assert div.got.node == div.expected.node  # the same node chose another variant


def test_a_removed_extension_is_blamed_on_the_content_node(
    tour: RecordedTour, tmp_path: Path
) -> None:
    """Without the engagement-gated part b, the replay finishes the POI where the
    recording played part b: `start_poi … part b → finish_poi`, both nodes named."""
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    visit = trees / "visit_poi.yaml"
    text = visit.read_text()
    start = text.index("                      - type: FailureIsSuccess")
    end = text.index("                      - {type: FinishPoi")
    visit.write_text(text[:start] + text[end:])
    site = load_site()
    div = Replay(tour.path, site, load_tree(trees / "tour.yaml", site)).run().divergence
    assert div is not None and div.expected is not None and div.got is not None
    assert differences(div.expected, div.got, site).startswith("start_poi poi POI1")
    assert "part b" in differences(div.expected, div.got, site)
    assert div.got.payload["type"] == "finish_poi"
    assert div.expected.node.startswith("PlayContent POI1 b")
    assert div.got.node.startswith("FinishPoi POI1")


def test_a_changed_engagement_gate_names_the_content_nodes_and_the_vote(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Recorded with a visitor whose engagement swings (the ``mixed`` faces): the vote
    over the first and last 15 % of a face-stream stop's samples decided whether part b
    played. Voting over another share of the same samples decides otherwise (a tie means
    no extension): the report names ``PlayContent <stop> b`` against ``FinishPoi <stop>``
    and shows the samples and both votes, as each side's deciding nodes read them.

    The samples a live tour records move with the machine's load (ticks fall where the
    event loop gets to them), so the test looks for the share that changes the decision
    instead of assuming one."""
    visitor = {"id": 7, "position": [103.0, 36.0], "facing": True, "faces": "mixed"}
    recorded = record_tour(tmp_path / "mixed.mcap", {"visitors": [visitor]})
    div = config = site = None
    for edge in (0.05, 0.02, 0.1, 0.3, 0.5, 0.01):
        config = changed_config(tmp_path, lambda d, e=edge: d["engagement"].update(edge=e))
        site = load_site(config)
        div = Replay(recorded.path, site, load_tree(site=site)).run().divergence
        if div is not None:
            break
    assert div is not None and div.expected is not None and div.got is not None
    assert config is not None and site is not None
    played, finished = (
        (div.expected, div.got)
        if div.expected.payload.get("type") == "start_poi"
        else (div.got, div.expected)
    )
    poi = str(played.payload["poi"])
    assert poi in ("POI1", "POI2") and played.payload["part"] == "b"
    assert finished.payload == {"type": "finish_poi", "poi": poi}
    assert played.node.startswith(f"PlayContent {poi} b (visit_poi.yaml:")
    assert finished.node.startswith(f"FinishPoi {poi} (visit_poi.yaml:")
    assert played.reads["/engaged"] == "True"
    assert played.reads["/engagement_decision"].startswith(f"{poi}: engaged: ")
    assert finished.reads["/engaged"] == "False"
    assert finished.reads["/engagement_decision"].startswith(f"{poi}: not engaged")
    assert finished.reads["/engagement"] == played.reads["/engagement"]  # same samples
    assert re.fullmatch(r"\d+ samples: (-?0\.\d\d ){8}\.\.\.", finished.reads["/engagement"])

    assert main(["replay", str(recorded.path), "--config", str(config), "--quiet"]) == 1
    out = capsys.readouterr().out
    assert "sent by PlayContent " in out and "/engagement_decision = " in out


def test_a_skipped_stop_is_reported_with_the_nodes_on_both_sides(tmp_path: Path) -> None:
    """Recorded: navigation to POI2 failed once and the retry got there. With one
    navigation attempt only, the replay gives up on POI2: where the recording sent the
    goal again, the replay's guided drive ends (follow-me off) on its way to skip it."""
    recorded = record_tour(
        tmp_path / "retry.mcap", {"navigation": {"failures": [{"poi": "POI2", "times": 1}]}}
    )
    assert recorded.outcome.code == 0
    config = changed_config(tmp_path, lambda d: d["navigation"].update(attempts=1))
    site = load_site(config)
    div = Replay(recorded.path, site, load_tree(site=site)).run().divergence
    assert div is not None and div.expected is not None and div.got is not None
    assert differences(div.expected, div.got, site) == (
        "/GotoWayPoint waypoint POI2a → follow_me on false"
    )
    assert div.expected.node.startswith("Navigate POI2 (goto.yaml:")  # the retry
    assert div.got.node.startswith("Guide to POI2 (visit_poi.yaml:")  # giving up on it


def test_a_corpus_is_replayed_in_parallel_and_summarised(
    tour: RecordedTour, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two morning tours (the same recording twice), an afternoon tour, a truncated copy
    and a corrupt file, with POI1's variant a moved to end at 10:00: the morning tours
    diverge at the variant choice, the afternoon one does not, the truncated one is
    recovered up to its cut (and still diverges there), the corrupt one is reported and
    skipped; the summary groups the divergences and the JSON report has every row."""
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    shutil.copy(tour.path, corpus / "a-morning.mcap")
    shutil.copy(tour.path, corpus / "b-morning.mcap")
    record_tour(corpus / "c-afternoon.mcap", {"start_time": "2026-06-01T15:10:00+02:00"})
    data = tour.path.read_bytes()
    (corpus / "d-truncated.mcap").write_bytes(data[: len(data) * 3 // 4])
    (corpus / "e-corrupt.mcap").write_bytes(data[:8] + bytes(range(256)) * 4)
    config = changed_config(tmp_path, lambda d: d["variants"]["POI1"][0].update(until="10:00"))
    report = tmp_path / "report.json"
    code = main(
        [
            "replay",
            str(corpus),
            "--config",
            str(config),
            "--jobs",
            "2",
            "--report",
            str(report),
            "--quiet",
        ]
    )
    assert code == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"{corpus / 'a-morning.mcap'}: diverged at +")
    assert lines[1].startswith(f"{corpus / 'b-morning.mcap'}: diverged at +")
    assert lines[2] == f"{corpus / 'c-afternoon.mcap'}: identical"
    assert lines[3].startswith(f"{corpus / 'd-truncated.mcap'}: diverged at +")
    assert lines[3].endswith(" s]") and "[d-truncated.mcap: cut short" in lines[3]
    assert lines[4].startswith(f"{corpus / 'e-corrupt.mcap'}: unreadable: ")
    assert "waypoint POI1a → POI1b" in lines[0] and "replayed: Navigate POI1" in lines[0]
    assert lines[5] == (
        "3 of 5 tours diverge: 3 at Navigate POI1: waypoint; 1 unreadable; 1 recovered from a cut"
    )
    rows = json.loads(report.read_text())
    assert [r["status"] for r in rows["tours"]] == [
        "diverged",
        "diverged",
        "identical",
        "diverged",
        "unreadable",
    ]
    assert rows["summary"]["by_signature"] == {"Navigate POI1: waypoint": 3}
    assert rows["tours"][4]["reason"]  # why it could not be read
    assert rows["tours"][3]["recovered"].startswith("d-truncated.mcap: cut short")


def test_json_report_names_nodes_reads_and_the_domain_diff(
    tour: RecordedTour, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = changed_config(tmp_path, lambda d: d["variants"]["POI1"][0].update(until="10:00"))
    assert (
        main(["replay", str(tour.path), "--config", str(config), "--format", "json", "--quiet"])
        == 1
    )
    out = json.loads(capsys.readouterr().out)
    div = out["divergence"]
    assert out["identical"] is False and div["differs"] == "waypoint POI1a → POI1b"
    assert div["what"] == "waypoint"
    assert div["recorded"]["node"].startswith("Navigate POI1 (goto.yaml:")
    assert div["replayed"]["node"] == div["recorded"]["node"]
    assert div["replayed"]["channel"] == "/GotoWayPoint"
    assert "/waypoint" not in div["replayed"]["reads"]  # Navigate reads only the clock


def test_a_recording_carries_the_tree_that_ran(tour: RecordedTour) -> None:
    """The tree's BT.CPP XML is on /frog_bt/tree: the recording explains itself."""
    from mcap.reader import make_reader

    from frog_bt.tree.btcpp import tree_xml
    from frog_bt.tree.loader import DEFAULT_TREE

    with open(tour.path, "rb") as f:
        trees = [
            json.loads(m.data)
            for _, c, m in make_reader(f).iter_messages()
            if c.topic == "/frog_bt/tree"
        ]
    assert len(trees) == 1 and trees[0]["format"] == "BehaviorTree.CPP v4"
    assert trees[0]["xml"] == tree_xml(DEFAULT_TREE, tour.site, FACTORY)


def test_the_viewer_shows_recorded_and_replayed_commands_and_the_divergence(
    tour: RecordedTour, tmp_path: Path
) -> None:
    from rerun.chunk import RrdReader

    config = changed_config(tmp_path, lambda d: d["variants"]["POI1"][0].update(until="10:00"))
    rrd = tmp_path / "what-if.rrd"
    assert (
        main(
            ["replay", str(tour.path), "--config", str(config), "--quiet", "--rerun", f"save:{rrd}"]
        )
        == 1
    )
    texts: dict[str, list[str]] = {}
    for chunk in RrdReader(rrd).stream():
        if chunk.entity_path.startswith("/log/replay/") and not chunk.is_static:
            batch = chunk.to_record_batch()
            if "TextLog:text" in batch.schema.names:
                texts.setdefault(chunk.entity_path, []).extend(
                    t for row in batch.column("TextLog:text").to_pylist() for t in row
                )
    recorded, replayed = texts["/log/replay/recorded"], texts["/log/replay/replayed"]
    assert len(recorded) == len(replayed) > 1  # two lanes, command for command
    assert recorded[-1].startswith("recorded: /GotoWayPoint waypoint POI1a  [Navigate POI1")
    assert replayed[-1].startswith("replayed: /GotoWayPoint waypoint POI1b  [Navigate POI1")
    assert texts["/log/replay/divergence"] == [
        f"divergence, command {len(recorded)}: waypoint POI1a → POI1b"
    ]
