"""`frog-bt report` over a seeded corpus of real recorded tours (scripts/corpus): the
figures against what the corpus was seeded with, the three outputs, the executor seam
(processes and a local dask cluster), and files that are cut short, foreign or pieces
of a resumed tour."""

from __future__ import annotations

import csv
import json
import shutil
import sys
from datetime import datetime
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest

from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.frontend.protocol import encode_datagram
from frog_bt.model import channels
from frog_bt.model.events import Datagram, FrontendIn, FrontendOut
from frog_bt.model.frontend import (
    AskTour,
    FinishPoi,
    FrontendMessage,
    StartPoi,
    Tour,
    UserPositive,
    message_fields,
)
from frog_bt.model.outcomes import TourState
from frog_bt.model.run import RUN_METADATA
from frog_bt.model.tours import StopVisit
from frog_bt.offline.report.facts import FileFacts, Piece, _Pieces
from frog_bt.offline.report.rows import Played, StopTime, join, rows
from frog_bt.recordings.mcapfile import open_recording
from frog_bt.recordings.reader import Item, Primed
from frog_bt.runtime.observer import attach_all

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from corpus_run import FAST, make
from relabel import relabel

SEED = 2  # one day: declines, engaged, declines, fault, wander_off, bored; 3 afternoon


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    out = tmp_path_factory.mktemp("season")
    # the robot at twice its speed, not the fast tours': the fault (5 simulated minutes
    # in) still strikes mid-tour
    fast = {**FAST, "navigation": {"speed": 1.2}}
    return out, make(out, days=1, per_day=6, seed=SEED, jobs=2, fast=fast)


def report(tmp_path: Path, *args: str) -> dict[str, Any]:
    target = tmp_path / "out.json"
    assert main(["report", *args, "--json", str(target), "--quiet"]) == 0
    return json.loads(target.read_text())


def test_the_figures_are_those_the_corpus_was_seeded_with(corpus, tmp_path) -> None:
    directory, manifest = corpus
    seeded = manifest["tours"]
    kinds = [t["kind"] for t in seeded]
    got = report(tmp_path, str(directory))
    t, tours = got["totals"], got["tours"]
    assert t["tours"] == len(seeded) == 6
    assert t["tours_per_day"] == {"2026-06-01": 6}
    hours: dict[str, int] = {}
    for s in seeded:
        hour = str(datetime.fromisoformat(s["start"]).hour)
        hours[hour] = hours.get(hour, 0) + 1
    span = range(min(map(int, hours)), max(map(int, hours)) + 1)
    assert t["tours_per_hour"] == {str(h): hours.get(str(h), 0) for h in span}  # gaps as 0
    # the fault aborts its tour; every other kind completes
    assert t["completed"] == len(seeded) - kinds.count("fault")
    assert [r["ended"] for r in tours] == ["aborted" if k == "fault" else "ended" for k in kinds]
    # one typed taxonomy, each event once: the fault (not its abort again), the
    # declines, the visitors lost
    causes = {(c["cause"], c["detail"]): c["events"] for c in t["failure_causes"]}
    expected = {
        ("fault", "motors"): kinds.count("fault"),
        ("invitation declined", ""): kinds.count("declines"),
        ("visitor lost", ""): kinds.count("wander_off"),
    }
    # A known race, not this report's: when the fault strikes as the robot arrives at a
    # stop, the stop's success may answer the drive home sent just after it, and the
    # robot then docks away from its charger (retried, counted once each as a dock retry).
    retries = causes.pop(("dock retry", ""), 0)
    assert retries == sum(r["dock_retries"] for r in tours if r["ended"] == "aborted")
    assert causes == {k: n for k, n in expected.items() if n}
    assert t["visitors_lost"] == kinds.count("wander_off")
    # the funnel: every visitor starts; one who wanders off reaches POI1 only
    funnel = t["funnel"]
    assert funnel["started"] == 6 + kinds.count("wander_off")
    assert funnel["POI1"] == 6 + kinds.count("wander_off")
    assert funnel["POI2"] == 6 and funnel["finished"] == 6 - kinds.count("fault")
    # rates carry their Wilson interval
    completion = t["rates"]["completion"]
    assert completion["k"] == t["completed"] and completion["n"] == 6
    assert completion["low"] < completion["rate"] <= completion["high"] <= 1.0
    # one invitation each; a second after a decline or a visitor who wandered off
    assert t["invitations"] == 6 + kinds.count("declines") + kinds.count("wander_off")
    assert t["invitations_declined"] == kinds.count("declines")
    assert [r["introduction"] for r in tours] == ["accepted"] * 6
    # the engagement gate: part b for every visitor but the bored one; a visitor who
    # wanders off on the way to POI2 has heard POI1, and so does the next one
    lost = kinds.count("wander_off")
    assert t["gate_decisions"] == {"POI1": 6 + lost, "POI2": 6}
    assert t["part_b_rate"] == {"POI1": (5 + lost) / (6 + lost), "POI2": 5 / 6}
    for r, kind in zip(tours, kinds, strict=True):
        engagement = r["engagement"]
        assert [e["poi"] for e in engagement] == (
            ["POI1", "POI1", "POI2"] if kind == "wander_off" else ["POI1", "POI2"]
        )
        assert {e["decision"] for e in engagement} == {"a only" if kind == "bored" else "b"}
        assert all(e["samples"] > 0 for e in engagement)
    # the time-of-day variant the site picks for the tour's start
    site = load_site()
    for r, s in zip(tours, seeded, strict=True):
        at = datetime.fromisoformat(s["start"]).time()
        assert r["variants"][0] == site.waypoint_for("POI1", at)
    assert t["distance_m"] > 0 and all(r["distance_m"] > 100 for r in tours)
    assert t["resumed"] == 0


def test_csv_parquet_and_a_self_contained_html(corpus, tmp_path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    directory, _ = corpus
    out = tmp_path / "r.html"
    assert (
        main(
            [
                "report",
                str(directory),
                "-o",
                str(out),
                "--csv",
                str(tmp_path / "r.csv"),
                "--parquet",
                str(tmp_path / "r.parquet"),
                "--quiet",
            ]
        )
        == 0
    )
    with open(tmp_path / "r.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert len(table) == 6 and table[0]["day"] == "2026-06-01"
    parquet = pq.read_table(tmp_path / "r.parquet")
    assert str(parquet.schema.field("day").type) == "date32[day]"
    assert str(parquet.schema.field("start").type) == "timestamp[us, tz=Europe/Madrid]"
    assert str(parquet.schema.field("stops_reached").type) == "list<element: string>"
    got = parquet.to_pylist()
    assert [r["tour"] for r in got] == [int(r["tour"]) for r in table]
    assert [r["ended"] for r in got] == [r["ended"] for r in table]
    assert ["; ".join(r["stops_reached"]) for r in got] == [r["stops_reached"] for r in table]

    class Page(HTMLParser):
        def __init__(self) -> None:
            super().__init__()
            self.images: list[str] = []
            self.links: list[str] = []
            self.in_totals = False
            self.totals = ""

        def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
            a = dict(attrs)
            if tag == "img":
                self.images.append(a.get("src") or "")
            for key in ("src", "href"):
                if a.get(key) and tag != "img":
                    self.links.append(a[key] or "")
            self.in_totals = tag == "script" and a.get("id") == "totals"

        def handle_data(self, data: str) -> None:
            if self.in_totals:
                self.totals += data

    page = Page()
    page.feed(out.read_text())
    assert len(page.images) >= 7
    assert all(src.startswith("data:image/png;base64,") for src in page.images)
    assert page.links == []  # nothing to fetch: it opens offline
    assert json.loads(page.totals)["tours"] == 6


def test_two_jobs_and_a_dask_cluster_give_the_same_rows(corpus, tmp_path) -> None:
    distributed = pytest.importorskip("distributed")
    directory, _ = corpus
    one = report(tmp_path, str(directory))
    two = report(tmp_path, str(directory), "--jobs", "2")
    assert two == one
    with distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp://",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        fleet = report(tmp_path, str(directory), "--scheduler", cluster.scheduler_address)
        first = sorted(directory.glob("*.mcap"))[0]
        assert (
            main(["replay", str(first), "--scheduler", cluster.scheduler_address, "--quiet"]) == 0
        )  # batch replay through the same seam: identical
    assert fleet == one


def test_a_cut_file_is_read_to_the_cut_and_a_foreign_one_is_skipped(
    corpus, tmp_path, capsys
) -> None:
    directory, _ = corpus
    files = sorted(directory.glob("*.mcap"))
    work = tmp_path / "mixed"
    work.mkdir()
    shutil.copy(files[0], work / files[0].name)
    data = files[1].read_bytes()
    (work / files[1].name).write_bytes(data[: len(data) // 2])  # killed half-way
    (work / "notes.mcap").write_text("not a recording")
    got = report(tmp_path, str(work))
    err = capsys.readouterr().err
    assert "skipped " in err and "notes.mcap: not an MCAP file" in err
    assert "cut short" in err
    assert got["totals"]["tours"] == 2 and got["totals"]["unreadable_files"] == 1
    assert [r["ended"] for r in got["tours"]] == ["ended", "cut"]
    # the outputs keep both: the file skipped with why, the one read in part with how much
    prov = got["totals"]["provenance"]
    assert [s.split(": ", 1)[1] for s in prov["skipped"]] == ["not an MCAP file"]
    ((cut,),) = [prov["cut_short"]]
    assert cut.startswith(str(work / files[1].name) + ": cut short") and "recovered" in cut


def test_the_pieces_of_a_tour_are_joined_into_one() -> None:
    site = load_site()
    # robot a: killed during POI2 (the halt said finish_poi), restarted at 410 (a file
    # of its own), the tour resumed at POI2
    before = Piece(
        file="a/1.mcap",
        started=100.0,
        started_seq=1,
        t0=100.0,
        t1=400.0,
        stops=[
            StopVisit("POI1", 200.0, "POI1a", "ab", 200.0, 220.0, arrived=True),
            StopVisit("POI2", 380.0, "POI2a", "a", 380.0, 400.0, arrived=True),
        ],
        distance=50.0,
    )
    after = Piece(
        file="a/2.mcap",
        t0=405.0,
        t1=900.0,
        ended="ended",
        end_seq=30,
        stops=[StopVisit("POI2", 450.0, "POI2a", "ab", 450.0, 480.0, arrived=True)],
        distance=70.0,
    )
    # robot b, the same hours: a rotation (the tour file opens just after `tour started`,
    # the end of the tour before resent into it), then a new executive whose first
    # `tour started` has seq 1 again: a new tour
    opened = Piece(file="b/1.mcap", started=390.0, started_seq=7, t0=390.0, t1=390.0)
    resent = Piece(file="b/2.mcap", t0=391.0, t1=391.0, ended="ended", end_seq=5)
    rotated = Piece(
        file="b/2.mcap",
        started=391.0,
        started_seq=7,
        t0=391.0,
        t1=600.0,
        ended="ended",
        end_seq=60,
        stops=[StopVisit("POI1", 410.0, "POI1a", "a", 410.0, 420.0, arrived=True)],
    )
    fresh = Piece(
        file="b/3.mcap",
        started=700.0,
        started_seq=7,
        t0=700.0,
        t1=800.0,
        ended="aborted",
        reason="operator",
    )
    files = [
        FileFacts("a/2.mcap", [after], restarts=[405.0]),
        FileFacts("b/3.mcap", [fresh], restarts=[650.0]),
        FileFacts("a/1.mcap", [before], restarts=[90.0]),
        FileFacts("b/2.mcap", [resent, rotated]),
        FileFacts("b/1.mcap", [opened], restarts=[1.0]),
    ]
    tours = join(files)
    assert [
        (t.robot, [Path(p.file).name for p in t.pieces], t.resumed, t.last.ended) for t in tours
    ] == [
        ("a", ["1.mcap", "2.mcap"], True, "ended"),
        ("b", ["1.mcap", "2.mcap", "2.mcap"], False, "ended"),
        ("b", ["3.mcap"], False, "aborted"),
    ]
    first = rows(files, site)[0]
    assert (
        first.robot,
        first.files,
        first.stops_reached,
        first.parts,
        first.distance_m,
        first.ended,
        first.duration_s,
        first.resumed,
    ) == (
        "a",
        ["1.mcap", "2.mcap"],
        ["POI1", "POI2"],
        [Played("POI1", "ab"), Played("POI2", "ab")],
        120.0,
        "ended",
        800.0,
        True,
    )
    assert first.time_at_stops == [StopTime("POI1", 20.0), StopTime("POI2", 50.0)]  # 20 + 30
    assert first.restarts == 1 and [str(i) for i in first.incidents] == ["restart"]


def _out(t: float, seq: int, message: FrontendMessage) -> list[tuple[float, Item]]:
    """A new command as the reader gives it: its datagram, then the event."""
    datagram = encode_datagram(message.type, seq, message_fields(message))
    return [(t, Datagram(t, "out", datagram)), (t, FrontendOut(t, message))]


def test_a_tour_file_opening_with_the_tour_befores_end_resent_is_read_whole() -> None:
    """The idle file between two tours was short: the tour before's `tour ended` (seq 5)
    is still being resent when the next tour's file opens, after its `tour started`
    (seq 7, acked at once). What follows in that file is the new tour's."""
    site = load_site()
    idle = _Pieces("r/1-idle.mcap", site)
    idle.first(100.0)
    idle.take(100.0, Primed(channels.Primer(frontend_out_seqs=[4, 5, 6]), ()))
    for t, item in _out(101.0, 7, Tour(TourState.STARTED, "")):
        idle.take(t, item)
    tour = _Pieces("r/2-tour.mcap", site)
    tour.first(101.1)
    for t, item in (
        *_out(101.2, 5, Tour(TourState.ENDED, "")),
        *_out(130.0, 9, AskTour(True)),
        (131.0, FrontendIn(131.0, UserPositive())),
        *_out(150.0, 10, StartPoi("POI1", "POI1a", "a")),
        *_out(170.0, 11, FinishPoi("POI1")),
        *_out(300.0, 20, Tour(TourState.ENDED, "")),
    ):
        tour.take(t, item)
    files = [
        FileFacts("r/1-idle.mcap", idle.finish(), restarts=[]),
        FileFacts("r/2-tour.mcap", tour.finish()),
    ]
    (row,) = rows(files, site)
    assert (
        row.invitations,
        row.invitations_accepted,
        row.stops_reached,
        row.ended,
        row.duration_s,
        row.resumed,
    ) == (1, 1, ["POI1"], "ended", 199.0, False)


def test_mistakes_are_one_line_and_exit_2(tmp_path, capsys) -> None:
    assert main(["report", str(tmp_path / "nowhere")]) == 2
    assert "no such file or directory" in capsys.readouterr().err
    assert main(["report", str(tmp_path)]) == 2
    assert "no recordings (*.mcap) found" in capsys.readouterr().err
    (tmp_path / "x.mcap").write_text("x")
    assert main(["report", str(tmp_path), "--jobs", "0"]) == 2
    assert "--jobs 0: expected 1 or more" in capsys.readouterr().err


def test_without_the_report_extra_it_says_which_before_reading(
    corpus, tmp_path, capsys, monkeypatch
) -> None:
    import importlib.util

    directory, _ = corpus
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "matplotlib" else real(name, *a),
    )
    out, table = tmp_path / "r.html", tmp_path / "r.csv"
    assert main(["report", str(directory), "-o", str(out), "--csv", str(table)]) == 2
    assert "needs matplotlib: pip install 'frog-bt[report]'" in capsys.readouterr().err
    assert not out.exists() and not table.exists()  # nothing half-written


def test_a_tour_resumed_by_a_restarted_executive_is_one_resumed_row(tmp_path) -> None:
    import asyncio

    from frog_bt.live.rotation import RecordingDir
    from frog_bt.rehearsal import Rehearsal
    from frog_bt.sim import scenario_from

    day, checkpoint = tmp_path / "day", tmp_path / "checkpoint.json"
    scenario = scenario_from(
        "default", {"speed": 1000.0, "content": {"default": 10, "introduction": 8}}
    )

    async def run() -> None:
        first_files = RecordingDir(day, 10**9)
        first = Rehearsal(
            scenario,
            site=load_site(),
            prepare=lambda exe: attach_all(exe, [first_files]),
            checkpoint=checkpoint,
            once=False,
            memory=True,
        )
        async with first:
            await first.sim.wait_for(
                lambda r: r.channel == "start_poi" and r.payload.get("poi") == "POI2", 60
            )
            first.own_sim = False  # the robot goes on; this executive stops (as if killed)
        first_files.close()
        second_files = RecordingDir(day, 10**9)
        try:
            async with Rehearsal(
                None,
                site=load_site(),
                sim=first.sim,
                listen=first.listen,
                prepare=lambda exe: attach_all(exe, [second_files]),
                checkpoint=checkpoint,
            ) as second:
                outcome = await second.finish()
                assert outcome.code == 0, outcome.reason
        finally:
            second_files.close()
            await first.sim.stop()

    asyncio.run(run())
    got = report(tmp_path, str(day))
    assert got["totals"]["tours"] == 1 and got["totals"]["resumed"] == 1
    (row,) = got["tours"]
    assert row["resumed"] and row["ended"] == "ended" and len(row["files"]) >= 3
    assert row["stops_reached"] == ["POI1", "POI2", "POI3", "POI4", "POI5", "END"]  # POI2 once
    # one run: the resumed executive's files keep the run id and name the run they resume
    runs = [open_recording(p).metadata[RUN_METADATA] for p in sorted(day.glob("*.mcap"))]
    assert len({r["id"] for r in runs}) == 1 and {r["robot"] for r in runs} == {"frog"}
    assert "resumes" not in runs[0] and runs[-1]["resumes"] == runs[-1]["id"]


def test_without_the_fleet_extra_scheduler_says_which(
    corpus, tmp_path, capsys, monkeypatch
) -> None:
    directory, _ = corpus
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    for command in ("report", "replay"):
        assert main([command, str(directory), "--scheduler", "tcp://127.0.0.1:1", "--quiet"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [
            f"frog-bt {command}: --scheduler needs dask.distributed: pip install 'frog-bt[fleet]'"
        ]


def test_a_copy_beside_its_original_is_skipped_not_counted_twice(corpus, tmp_path) -> None:
    """A file copied whole and a copy cut short put beside the original are the same run
    (their run id) overlapping in time: both are skipped and say why; the tour is counted
    once, as from the original alone."""
    directory, _ = corpus
    original = sorted(directory.glob("*.mcap"))[0]
    alone, both = tmp_path / "alone", tmp_path / "both"
    alone.mkdir()
    both.mkdir()
    shutil.copy(original, alone / original.name)
    shutil.copy(original, both / original.name)
    shutil.copy(original, both / "whole.mcap")
    data = original.read_bytes()
    (both / "copy.mcap").write_bytes(data[: len(data) // 2])
    one = report(tmp_path, str(alone))
    got = report(tmp_path, str(both))
    copy, whole = sorted(got["totals"]["provenance"]["skipped"])
    same = f": the same run as {original.name} (run "
    assert copy.startswith(f"{both / 'copy.mcap'}{same}") and whole.startswith(
        f"{both / 'whole.mcap'}{same}"
    )
    assert whole.endswith("and overlaps it in time: a copy (the longer one is read)")
    assert got["totals"]["tours"] == 1 and got["totals"]["provenance"]["runs"] == 1
    assert got["totals"]["provenance"]["suspicious"] == []
    keep = ("approaches", "invitations", "visitors", "distance_m", "stops_reached", "ended")
    assert [{k: r[k] for k in keep} for r in got["tours"]] == [
        {k: r[k] for k in keep} for r in one["tours"]
    ]


def test_files_recorded_before_run_ids_keep_the_copy_rule_by_time(corpus, tmp_path) -> None:
    """Without run ids (files from before them), one directory is one robot's and a file
    overlapping another in time is taken for a copy, as before, and says so."""
    directory, _ = corpus
    original = sorted(directory.glob("*.mcap"))[0]
    old = tmp_path / "old"
    old.mkdir()
    relabel(original, old / original.name, lambda _run: None)
    data = (old / original.name).read_bytes()
    (old / "copy.mcap").write_bytes(data[: len(data) // 2])
    got = report(tmp_path, str(old))
    prov = got["totals"]["provenance"]
    assert prov["skipped"] == [
        f"{old / 'copy.mcap'}: overlaps {original.name} in time, which one robot's recordings "
        "cannot: a copy? (no run id, recorded before run ids: the longer one is read)"
    ]
    assert (prov["runs"], prov["without_run_id"], got["totals"]["tours"]) == (0, 1, 1)
