"""`frog-bt report` over one robot's `--record DIR` recordings of tours of every kind
(tests/report/robot_day.py): each row held against what the simulator received during
that tour and against what its kind of tour does; a resumed tour, resends across a
rotation, cut and foreign files, two robots, and the three outputs read back."""

from __future__ import annotations

import csv
import json
import shutil
import uuid
from collections import Counter
from datetime import datetime
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer
from relabel import relabel
from robot_day import KINDS, RESTART_INTO_POI2_S, Seen

from frog_bt.cli import main
from frog_bt.recordings.mcapfile import open_recording

STOPS = ["POI1", "POI2", "POI3", "POI4", "POI5", "END"]  # content stops, in order


def report(tmp_path: Path, *args: str) -> dict[str, Any]:
    target = tmp_path / "out.json"
    assert main(["report", *args, "--json", str(target), "--quiet"]) == 0
    return json.loads(target.read_text())


def stop_seconds(row: dict[str, Any]) -> dict[str, float]:
    return {s["poi"]: s["seconds"] for s in row["time_at_stops"]}


def causes(row: dict[str, Any]) -> list[tuple[str, str]]:
    return [(i["cause"], i["detail"]) for i in row["incidents"]]


def day_of(kind: str) -> str:
    return KINDS[kind][2][:10]


@pytest.fixture(scope="module")
def by_kind(robot_day, tmp_path_factory) -> dict[str, dict[str, Any]]:
    directory, _ = robot_day
    got = report(tmp_path_factory.mktemp("report"), str(directory))
    days = {day_of(kind): kind for kind in KINDS}
    assert len(got["tours"]) == len(KINDS)  # one row per tour, whatever its files
    return {days[r["day"]]: r for r in got["tours"]} | {"totals": got["totals"]}


def visits(seen: Seen, restarted: bool = False) -> list[list[str]]:
    """[poi, parts, waypoint] of each visit, as the simulator received them; a visit
    a restart cut and the resumed executive played again is one."""
    out: list[list[str]] = []
    for m in seen.of("start_poi"):
        if m["part"] == "b":
            out[-1][1] += "b"
        elif restarted and out and out[-1][0] == m["poi"]:
            out[-1][2] = m["waypoint"]
        else:
            out.append([m["poi"], "a", m["waypoint"]])
    return out


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_row_is_what_the_robot_was_told_and_did(robot_day, by_kind, kind) -> None:
    _, seen_all = robot_day
    seen, row = seen_all[kind], by_kind[kind]
    v = visits(seen, restarted=kind == "resumed")
    # every content visit is reached but those skipped (a skip is never also reached)
    left = {s["poi"] for s in row["stops_skipped"]}
    assert row["stops_reached"] == [poi for poi, _, _ in v if poi not in left]
    assert set(row["stops_played"]) <= set(row["stops_reached"])
    assert row["parts"] == [{"poi": poi, "parts": parts} for poi, parts, _ in v]
    assert row["variants"] == list(dict.fromkeys(wp for poi, _, wp in v if wp != poi))
    assert row["approaches"] == sum(t == "/ApproachPeopleFar" for t, _ in seen.ros)
    assert row["invitations"] == len(seen.of("ask_tour"))
    assert row["invitations_accepted"] == seen.answers.count("user_positive")
    assert row["invitations_declined"] == seen.answers.count("user_negative")
    last = seen.of("tour")[-1]
    assert (row["ended"], row["reason"]) == (last["state"], last["reason"])
    start = datetime.fromisoformat(KINDS[kind][2])
    assert (row["day"], row["hour"]) == (f"{start:%Y-%m-%d}", start.hour)
    # on the executives' clock, as recorded: equal but for the row's rounding to 0.1 s
    assert row["duration_s"] == pytest.approx(seen.duration, abs=0.051)
    assert row["distance_m"] == pytest.approx(seen.path_m, rel=0.01, abs=1.0)
    assert row["resumed"] is (kind == "resumed")
    assert row["robot"] == "frog1"
    seconds = stop_seconds(row)
    assert list(seconds) == list(dict.fromkeys(poi for poi, _, _ in v))
    assert all(s > 0 for s in seconds.values())


def test_what_each_kind_of_tour_shows(by_kind) -> None:
    def gate(kind: str) -> list[tuple[str, str]]:
        return [(e["poi"], e["decision"]) for e in by_kind[kind]["engagement"]]

    # the time-of-day variants: after 13:00 the afternoon waypoints
    assert by_kind["afternoon"]["variants"] == ["POI1b", "POI2b"]
    assert by_kind["bored"]["variants"] == ["POI1a", "POI2a"]
    # the engagement gate: part b for an engaged visitor, none for a bored one
    assert gate("afternoon") == [("POI1", "b"), ("POI2", "b")]
    assert gate("bored") == [("POI1", "a only"), ("POI2", "a only")]
    for e in by_kind["bored"]["engagement"]:
        assert e["samples"] > 0 and e["edge_engaged"] == 0 and e["edge_votes"] > 0
    for e in by_kind["afternoon"]["engagement"]:
        assert e["edge_engaged"] == e["edge_votes"] > 0
    assert by_kind["bored"]["parts"] == [{"poi": s, "parts": "a"} for s in STOPS]
    # a visitor says no, another says yes: one tour, two invitations, one visitor
    declines = by_kind["declines"]
    assert (
        declines["approaches"],
        declines["approaches_accepted"],
        declines["visitors"],
        declines["invitations"],
        declines["invitations_accepted"],
        declines["invitations_declined"],
        declines["introduction"],
    ) == (2, 2, 1, 2, 1, 1, "accepted")
    # a no, and the operator sends the robot home: declined, aborted, nothing visited
    home = by_kind["declined_then_home"]
    assert (
        home["introduction"],
        home["ended"],
        home["reason"],
        [(c["command"], c["ok"]) for c in home["operator"]],
        home["stops_reached"],
        home["stops_skipped"],
        home["visitors"],
        home["interventions"],
    ) == ("declined", "aborted", "operator", [("home", True)], [], [], 0, 1)
    assert causes(home) == [("invitation declined", ""), ("operator", "home")]
    # POI1 cannot be reached: three goals (two retries), skipped with its reason
    nav = by_kind["nav_failure"]
    assert nav["stops_skipped"] == [{"poi": "POI1", "why": "navigation failed"}]
    assert nav["stops_reached"] == STOPS[1:]
    assert causes(nav).count(("navigation retry", "")) == 2
    assert ("stop given up", "POI1") in causes(nav)
    assert (nav["nav_retries"], nav["dock_retries"]) == (2, 0)
    assert gate("nav_failure") == [("POI2", "b")]
    # a motor fault on the way: the tour aborted with its reason, the fault listed
    fault = by_kind["fault"]
    assert (fault["ended"], fault["reason"], fault["faults"]) == (
        "aborted",
        "electronics fault: motors: motor driver overheated",
        ["motors: motor driver overheated"],
    )
    assert fault["stops_skipped"] == []  # it never reached the stops after the abort
    # the alert raised as it aborts is the tour's; the fault is counted once
    assert [(a["kind"], a["severity"]) for a in fault["alerts"]] == [("fault", "ERROR")]
    assert causes(fault) == [("fault", "motors")]
    # the operator skips POI3 during its content and POI4 on the way there
    skips = by_kind["operator_skips"]
    assert skips["stops_skipped"] == [
        {"poi": "POI3", "why": "operator"},
        {"poi": "POI4", "why": "operator"},
    ]
    # POI3's content started, but it was left: not reached, not played (issue 39)
    assert skips["stops_reached"] == skips["stops_played"] == ["POI1", "POI2", "POI5", "END"]
    assert [(c["command"], c["ok"]) for c in skips["operator"]] == [("skip", True)] * 2
    assert skips["interventions"] == 2
    assert causes(skips) == [("operator", "skip")] * 2
    # the first undock fails and is tried again
    assert (
        by_kind["undock_failure"]["dock_retries"],
        by_kind["undock_failure"]["nav_retries"],
    ) == (1, 0)
    # a visitor lost on the way: back to POI0, a second visitor, POI1 again for them
    wander = by_kind["wander_off"]
    assert (wander["visitors"], wander["approaches"], wander["invitations"]) == (2, 2, 2)
    assert wander["stops_reached"] == ["POI1", *STOPS]
    assert wander["visitors_lost"] == 1 and causes(wander) == [("visitor lost", "")]
    assert (
        stop_seconds(wander)["POI1"] > stop_seconds(by_kind["afternoon"])["POI1"] * 1.5
    )  # both visits added
    for kind in KINDS:
        if kind != "undock_failure":
            assert by_kind[kind]["dock_retries"] == 0, kind
        if kind != "nav_failure":
            assert by_kind[kind]["nav_retries"] == 0, kind


def test_a_tour_resumed_after_a_restart_is_one_row(by_kind) -> None:
    row = by_kind["resumed"]
    # idle and tour file of the first executive, idle and tour file of the second
    assert len(row["files"]) == 4
    assert row["resumed"] is True and row["ended"] == "ended"
    assert row["stops_reached"] == STOPS  # POI2, cut by the restart, once
    assert row["parts"] == [
        {"poi": s, "parts": "ab" if s in ("POI1", "POI2") else "a"} for s in STOPS
    ]
    assert row["restarts"] == 1 and causes(row) == [("restart", "")]
    assert (row["approaches"], row["invitations"], row["visitors"]) == (1, 1, 1)
    # POI2's time: what part a played before the restart (at least the seconds the first
    # executive ran on into it) and the whole visit after it
    others = [stop_seconds(by_kind[k])["POI2"] for k in ("afternoon", "declines", "undock_failure")]
    assert stop_seconds(row)["POI2"] >= max(others) + RESTART_INTO_POI2_S - 0.1
    assert by_kind["totals"]["resumed"] == 1


def test_resends_across_a_rotation_are_not_new_tours(robot_day, by_kind) -> None:
    directory, _ = robot_day
    tour_file = next(directory.glob(f"{day_of('unacked').replace('-', '')}-*-tour*.mcap"))
    started = [
        json.loads(data)
        for topic, _, data in open_recording(tour_file).messages()
        if topic == "/frontend/out" and b'"started"' in data
    ]
    assert started  # `tour started`, unacked, sent again after the rotation
    row = by_kind["unacked"]
    assert len(row["files"]) == 2 and row["ended"] == "ended"
    assert row["resumed"] is False


def test_the_totals_and_rates(robot_day, by_kind) -> None:
    _, seen = robot_day
    t = by_kind["totals"]
    aborted = 2  # the fault, and the decliner sent home
    assert t["tours"] == len(KINDS) and t["completed"] == len(KINDS) - aborted
    assert t["completion_rate"] == pytest.approx((len(KINDS) - aborted) / len(KINDS))
    assert t["tours_per_day"] == {day_of(kind): 1 for kind in KINDS}
    # the hours with no tours are there, as zero
    assert t["tours_per_hour"] == {
        "10": len(KINDS) - 2,
        "11": 1,
        "12": 0,
        "13": 0,
        "14": 0,
        "15": 1,
    }
    answers = [a for s in seen.values() for a in s.answers]
    assert t["invitations"] == len(answers)
    assert t["invitation_acceptance"] == pytest.approx(
        answers.count("user_positive") / len(answers)
    )
    assert t["approaches"] == sum(
        topic == "/ApproachPeopleFar" for s in seen.values() for topic, _ in s.ros
    )
    assert t["approach_success"] == 1.0  # every simulated approach reaches its person
    # one each; none for the decliner sent home, two for the tour that lost its first
    assert t["visitors"] == sum(by_kind[k]["visitors"] for k in KINDS) == len(KINDS)
    for poi in ("POI1", "POI2"):
        decided = [
            parts for k in KINDS for p, parts, _ in visits(seen[k], k == "resumed") if p == poi
        ]
        assert t["gate_decisions"][poi] == len(decided)
        assert t["part_b_rate"][poi] == pytest.approx(
            sum("b" in parts for parts in decided) / len(decided)
        )
    assert {(c["cause"], c["detail"]): c["events"] for c in t["failure_causes"]} == {
        ("operator", "skip"): 2,
        ("operator", "home"): 1,
        ("navigation retry", ""): 2,
        ("stop given up", "POI1"): 1,
        ("fault", "motors"): 1,
        ("invitation declined", ""): 2,
        ("visitor lost", ""): 1,
        ("dock retry", ""): 1,
        ("restart", ""): 1,
    }
    # the field reliability: interventions told apart, per 100 tours
    rel = t["reliability"]
    assert rel["interventions"] == {
        "help answered": 0,
        "home": 1,
        "skip": 2,
        "alert acknowledged": 0,
    }
    assert rel["interventions_per_100_tours"] == pytest.approx(round(300 / len(KINDS), 1))
    assert rel["failures_needing_a_person"] == 1  # the fault (an ERROR alert)
    assert rel["robot_days"] == len(KINDS) and rel["hours_in_service"] > 0
    assert 0 < rel["autonomy"] < 1
    assert rel["km_per_robot_day"] == pytest.approx(
        sum(s.path_m for s in seen.values()) / 1000 / len(KINDS), rel=0.02
    )
    assert t["distance_m"] == pytest.approx(sum(s.path_m for s in seen.values()), rel=0.01)
    played = Counter(
        wp for k in KINDS for wp in {wp for poi, _, wp in visits(seen[k]) if wp != poi}
    )
    assert t["variants"] == dict(played) and played["POI1b"] == played["POI2b"] == 1


def test_csv_and_parquet_read_back_as_the_rows(robot_day, tmp_path) -> None:
    pq = pytest.importorskip("pyarrow.parquet")
    directory, _ = robot_day
    got = report(
        tmp_path,
        str(directory),
        "--csv",
        str(tmp_path / "r.csv"),
        "--parquet",
        str(tmp_path / "r.parquet"),
    )
    with open(tmp_path / "r.csv", newline="", encoding="utf-8") as f:
        table = list(csv.DictReader(f))
    assert [r["tour"] for r in table] == [str(r["tour"]) for r in got["tours"]]
    for line, r in zip(table, got["tours"], strict=True):
        assert line["stops_reached"] == "; ".join(r["stops_reached"])
        assert line["start"] == r["start"] and line["ended"] == r["ended"]
    parquet = pq.read_table(tmp_path / "r.parquet").to_pylist()
    for p, r in zip(parquet, got["tours"], strict=True):
        assert p["day"].isoformat() == r["day"]
        assert p["start"].isoformat() == r["start"]
        assert {**p, "day": r["day"], "start": r["start"]} == r


class Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.images: list[str] = []
        self.links: list[str] = []
        self.script: str | None = None
        self.scripts: dict[str, str] = {}
        self.text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag == "img":
            self.images.append(a.get("src") or "")
        elif a.get("src") or a.get("href"):
            self.links.append(a.get("src") or a.get("href") or "")
        self.script = a.get("id") if tag == "script" else None

    def handle_data(self, data: str) -> None:
        if self.script:
            self.scripts[self.script] = self.scripts.get(self.script, "") + data
        self.text.append(data)


def test_the_html_is_one_self_contained_page(robot_day, tmp_path) -> None:
    pytest.importorskip("matplotlib")
    directory, _ = robot_day
    got = report(tmp_path, str(directory), "-o", str(tmp_path / "r.html"))
    page = Page()
    page.feed((tmp_path / "r.html").read_text(encoding="utf-8"))
    # per day, per hour, part b, length, per stop, funnel, daily trends, distance
    assert len(page.images) == 8
    assert all(src.startswith("data:image/png;base64,") for src in page.images)
    assert page.links == []  # nothing fetched: it opens offline
    assert json.loads(page.scripts["totals"]) == got["totals"]
    text = " ".join(page.text)
    t = got["totals"]
    # to its precision: eleven tours' interval is tens of points wide, so whole points
    shown = f"{100 * t['completion_rate']:.0f} % ({t['completed']} of {t['tours']}; "
    assert shown in text and "Failure causes (each event once)" in text
    assert "stop given up" in text and "Field reliability" in text
    assert "innerHTML" not in (tmp_path / "r.html").read_text(encoding="utf-8")


def test_cut_and_foreign_files_are_said_and_the_rest_is_read(robot_day, tmp_path, capsys) -> None:
    directory, _ = robot_day
    work = tmp_path / "frog1"
    shutil.copytree(directory, work)
    first_tour = sorted(work.glob(f"{day_of('resumed').replace('-', '')}-*-tour*.mcap"))[0]
    data = first_tour.read_bytes()
    first_tour.write_bytes(data[: len(data) * 2 // 3])  # killed: its last third is gone
    idle = sorted(work.glob(f"{day_of('declined_then_home').replace('-', '')}-*-idle*"))[0]
    idle.write_bytes(idle.read_bytes()[:40])  # nothing readable left: `tour started` lost
    (work / "notes.mcap").write_text("not a recording")
    foreign = work / "chatter.mcap"
    with open(foreign, "wb") as f:
        writer = Writer(f)
        writer.start()
        schema = writer.register_schema("std_msgs/String", "jsonschema", b"{}")
        channel = writer.register_channel("/chatter", "json", schema)
        writer.add_message(channel, 1, b'{"data": "hi"}', 1, 1)
        writer.finish()
    got = report(tmp_path, str(work))
    err = capsys.readouterr().err
    assert f"skipped {work / 'notes.mcap'}: not an MCAP file" in err
    assert f"skipped {foreign}: not a frog-bt tour recording (no /frontend/out)" in err
    assert f"skipped {idle}: damaged MCAP file, nothing readable in it" in err
    assert f"{first_tour}: cut short (no summary or footer): recovered" in err
    t = got["totals"]
    assert t["tours"] == len(KINDS) and t["unreadable_files"] == 3
    rows = {r["day"]: r for r in got["tours"]}
    resumed = rows[day_of("resumed")]
    assert resumed["resumed"] is True and resumed["ended"] == "ended"
    assert resumed["stops_reached"][-4:] == ["POI3", "POI4", "POI5", "END"]
    home = rows[day_of("declined_then_home")]  # from its tour file alone
    assert (home["ended"], home["introduction"], home["resumed"]) == ("aborted", "declined", False)


def test_two_robots_tours_at_the_same_time_stay_apart(robot_day, tmp_path) -> None:
    """One robot's resumed tour, and the same recordings as another robot's run (another
    run id, another name): two tours, each joined from its own run's files."""
    directory, _ = robot_day
    day = day_of("resumed").replace("-", "")
    other: dict[str, str] = {}  # frog1's run id -> frog2's

    def frog2(run: dict[str, str]) -> dict[str, str]:
        new = other.setdefault(run["id"], str(uuid.uuid4()))
        return {**run, "id": new, "robot": "frog2"} | ({"resumes": new} if "resumes" in run else {})

    for robot in ("frog1", "frog2"):
        (tmp_path / robot).mkdir()
        for path in directory.glob(f"{day}-*.mcap"):
            if robot == "frog1":
                shutil.copy(path, tmp_path / robot / path.name)
            else:
                relabel(path, tmp_path / robot / path.name, frog2)
    got = report(tmp_path, str(tmp_path / "frog1"), str(tmp_path / "frog2"))
    assert got["totals"]["provenance"]["skipped"] == []
    assert got["totals"]["provenance"]["suspicious"] == []
    assert [(r["robot"], r["resumed"], r["stops_reached"]) for r in got["tours"]] == [
        ("frog1", True, STOPS),
        ("frog2", True, STOPS),
    ]


def test_one_job_two_jobs_alike(robot_day, tmp_path) -> None:
    directory, _ = robot_day
    assert report(tmp_path, str(directory), "--jobs", "2") == report(tmp_path, str(directory))
