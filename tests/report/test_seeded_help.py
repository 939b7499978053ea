"""`frog-bt report` over a small seeded season with one tour of each help event
(scripts/corpus_run.py: a dock answered ``done_by_hand``, an operator ``home`` and
``skip``, a ``battery_low`` acknowledged after a known delay, a restart) held against
its manifest: the interventions told apart, per 100 tours, the time to acknowledge, the
funnel and the failure taxonomy with each cause counted once; ``replay`` of the season
finds no divergence; and ``--compare`` of two tiny seasons that differ in one seeded
rate."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from collections import Counter
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest

from frog_bt import __version__
from frog_bt.cli import main
from frog_bt.clock import SITE_TZ
from frog_bt.config import fingerprint, load_site
from tests import seasons
from tests.recording.recorded_tour import FAST_TOURS  # tours in under a second

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from check_report import autonomy
from corpus_run import HELP_KINDS, make

# seasons.HELPED: 7 tours, one of each help kind, a bored visitor, a navigation failure
DOCK_ATTEMPTS = 3  # config/site.yaml docking.attempts: all fail, then the robot asks


@pytest.fixture(scope="module")
def season(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    out, manifest = seasons.season(tmp_path_factory, "helped", **seasons.HELPED)
    for run, tour in zip(manifest["runs"], manifest["tours"], strict=True):
        assert run["code"] == (1 if tour["kind"] == "home" else 0), run
    return out, manifest


def report(tmp_path: Path, *args: str) -> dict[str, Any]:
    target = tmp_path / "out.json"
    assert main(["report", *args, "--json", str(target), "--quiet"]) == 0
    return json.loads(target.read_text())


def test_the_help_events_are_those_seeded(season, tmp_path) -> None:
    directory, manifest = season
    kinds = [t["kind"] for t in manifest["tours"]]
    count = Counter(kinds)
    assert {k: count[k] for k in HELP_KINDS} == dict.fromkeys(HELP_KINDS, 1)
    assert manifest["help"]["each"] == 1
    n = len(kinds)
    got = report(tmp_path, str(directory))
    t, tours = got["totals"], got["tours"]
    assert t["tours"] == n and t["resumed"] == count["restart"]
    assert [r["ended"] for r in tours] == ["aborted" if k == "home" else "ended" for k in kinds]
    assert t["completed"] == n - count["home"] - count["fault"]

    # the interventions, told apart, and per 100 tours
    rel = t["reliability"]
    want = {
        "help answered": count["dock_help"],
        "home": count["home"],
        "skip": count["skip"],
        "alert acknowledged": count["ack_alert"],
    }
    assert rel["interventions"] == want
    assert rel["interventions_per_100_tours"] == round(100 * sum(want.values()) / n, 1)
    for r, kind in zip(tours, kinds, strict=True):
        assert r["interventions"] == (
            1 if kind in ("dock_help", "home", "skip", "ack_alert") else 0
        )
        ops = [c["command"] for c in r["operator"] if c["ok"]]
        assert ops == {
            "dock_help": ["done_by_hand"],
            "home": ["home"],
            "skip": ["skip"],
            "ack_alert": ["ack_alert"],
        }.get(kind, [])
    # the time to acknowledge: the battery alerts, acknowledged the seeded delay after
    # their raise (the executive applies an answer at its next tick)
    ack = manifest["help"]["ack_after_s"]
    assert rel["acknowledged"] == count["ack_alert"]
    assert rel["time_to_acknowledge_s"]["median"] == pytest.approx(ack, abs=1.0)
    (alert,) = next(r for r, k in zip(tours, kinds, strict=True) if k == "ack_alert")["alerts"]
    assert alert["kind"] == "battery_low" and alert["acknowledged_s"] == pytest.approx(ack, abs=1.0)
    # the help request and the fault alerts are the failures that needed a person
    assert rel["failures_needing_a_person"] == count["dock_help"] + count["fault"]
    # autonomy: the time in service in hours when no one was needed, against the spans
    # and the moments the corpus heard as it recorded (each answer, each ERROR alert)
    assert all(
        run["needed"]
        for run, k in zip(manifest["runs"], kinds, strict=True)
        if k in ("dock_help", "home", "skip", "ack_alert")
    )
    heard = autonomy(manifest)
    assert heard is not None and 0.0 < heard < 1.0
    assert rel["autonomy"] == pytest.approx(heard, abs=0.002)

    # the funnel: the wanderer's visitor reaches POI1 only, and the next one starts
    # again; the visitor sent home at POI3 reaches no later stop
    funnel = t["funnel"]
    started = n + count["wander_off"]
    assert funnel["started"] == funnel["POI1"] == started
    assert funnel["POI2"] == n
    assert funnel["POI3"] == n - count["skip"]  # left during its content: not reached
    assert funnel["POI4"] == funnel["POI5"] == n - count["home"] - count["fault"]
    assert funnel["finished"] == n - count["home"] - count["fault"]

    # the taxonomy, each cause once: the home's abort, the restart's unrecorded stop and
    # the done_by_hand's help alert are not counted again
    causes = {(c["cause"], c["detail"]): c["events"] for c in t["failure_causes"]}
    expected = {
        ("help needed", "docking_failed"): count["dock_help"],
        ("dock retry", ""): (DOCK_ATTEMPTS - 1) * count["dock_help"],
        ("operator", "home"): count["home"],
        ("operator", "skip"): count["skip"],
        ("alert", "battery_low"): count["ack_alert"],
        ("restart", ""): count["restart"],
        ("visitor lost", ""): count["wander_off"],
        ("invitation declined", ""): count["declines"],
        ("fault", "motors"): count["fault"],
        ("navigation retry", ""): count["nav_failure"],
    }
    causes.pop(("approach rejected", ""), None)
    assert causes == {k: v for k, v in expected.items() if v}
    for r in tours:  # in a tour, no cause twice but the dock's retries
        once = [(i["cause"], i["detail"]) for i in r["incidents"] if i["cause"] != "dock retry"]
        assert len(once) == len(set(once)), r["incidents"]
    # the resumed tour: its two files, joined; the day is one robot's
    assert rel["robot_days"] == 1
    resumed = next(r for r, k in zip(tours, kinds, strict=True) if k == "restart")
    assert resumed["resumed"] and resumed["restarts"] == 1 and len(resumed["files"]) == 2
    assert resumed["stops_skipped"] == []


def test_compare_tells_the_seeded_difference_from_the_same_rate(tmp_path) -> None:
    """Two tiny seasons, one of engaged visitors and one of bored ones: part b differs
    (its interval leaves 0 out), completion does not (its interval holds 0)."""
    a, b = tmp_path / "a", tmp_path / "b"
    make(a, days=1, per_day=3, seed=2, jobs=2, weights={"engaged": 1.0}, fast=FAST_TOURS)
    make(b, days=1, per_day=3, seed=2, jobs=2, weights={"bored": 1.0}, fast=FAST_TOURS)
    got = report(tmp_path, str(a), "--compare", str(b))["totals"]["compare"]["rates"]
    part_b = got["part_b:POI2"]
    assert (part_b["a"]["rate"], part_b["b"]["rate"], part_b["difference"]) == (1.0, 0.0, -1.0)
    assert part_b["significant"] and part_b["high"] < 0
    completion = got["completion"]
    assert completion["difference"] == 0.0 and not completion["significant"]
    assert completion["low"] < 0 < completion["high"]
    # the page shows it too: a table under the summary, a row per rate, and B's files
    # that were skipped (here one that is not a recording), each with why
    (b / "notes.mcap").write_text("not a recording")
    html = tmp_path / "c.html"
    assert main(["report", str(a), "--compare", str(b), "-o", str(html), "--quiet"]) == 0
    assert f"<li>{b / 'notes.mcap'}: not an MCAP file</li>" in html.read_text()
    table = html.read_text().split('id="compare">', 1)[1].split("</table>", 1)[0]
    cells = {
        row[0]: row
        for row in (re.findall(r"<td>(.*?)</td>", r) for r in table.split("<tr>"))
        if row
    }
    assert cells["Part b at POI2"][3] == "-100 points" and cells["Part b at POI2"][5] == "yes"
    assert cells["Completion rate"][3] == "+0 points" and cells["Completion rate"][5] == "no"
    # every headline figure of the page, under the page's own label, each difference
    # with its interval (a count or total measured whole says it has none)
    page = html.read_text()
    labels = [
        label
        for ident in ("summary", "reliability")
        for label in re.findall(
            r"<tr><th>(.*?)</th>", page.split(f'id="{ident}">', 1)[1].split("</table>", 1)[0]
        )
    ]
    assert len(labels) >= 18 and "Tours per hour in service" in labels
    assert "Interventions per 100 tours" in labels and "Time to acknowledge an alert" in labels
    assert [label for label in cells if label != "figure"] == labels
    for label in labels:
        moved, interval = cells[label][3], cells[label][4]
        if moved != "\u2013":
            assert re.fullmatch(r"[+-]\d+(\.\d+)?( \S+)?", moved), (label, moved)
            assert interval in ("measured: none", "too few for an interval") or re.fullmatch(
                r"[+-]\d+(\.\d+)? to [+-]\d+(\.\d+)?", interval
            ), (label, interval)
    for label in (
        "Tours per hour in service",
        "Interventions per 100 tours",
        "Autonomy (hours with no one needed)",
        "Completion rate",
    ):
        assert " to " in cells[label][4], (label, cells[label])
    assert cells["Hours in service"][4] == "measured: none"
    figures = json.loads(
        page.split('<script type="application/json" id="totals">', 1)[1].split("</script>")[0]
    )["compare"]["figures"]
    assert [f["label"] for f in figures] == labels


def test_compare_mistakes_are_named(tmp_path, capsys) -> None:
    empty, some = tmp_path / "empty", tmp_path / "some"
    empty.mkdir()
    some.mkdir()
    (some / "junk.mcap").write_bytes(b"not a recording")
    assert main(["report", str(some), "--compare", str(empty), "--quiet"]) == 2
    assert f"no recordings (*.mcap) found in {empty}" in capsys.readouterr().err
    assert main(["report", str(empty), "--quiet"]) == 2
    assert f"found in {empty}" in capsys.readouterr().err
    assert main(["report", str(some), "--compare", str(some), "--quiet"]) == 2
    assert "the same recordings on both sides" in capsys.readouterr().err


def test_check_report_holds_the_season(season) -> None:
    """scripts/check_report.py, as run on the 200-tour season (docs/REPORT.md), holds
    this one too: its checks of the three outputs all pass."""
    directory, _ = season
    script = Path(__file__).resolve().parents[2] / "scripts" / "check_report.py"
    done = subprocess.run(
        [sys.executable, str(script), str(directory), "--jobs", "1"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "FAIL" not in done.stdout and "7 tours: all checks hold" in done.stdout
    assert "ok   autonomy" in done.stdout  # the manifest has what autonomy is held to


def test_provenance_names_what_wrote_and_ran_every_file(season, tmp_path) -> None:
    """The date range (local), the version, the tree and the site configuration that ran
    (hashed at start, in every file) and the files skipped, each with its reason."""
    directory, manifest = season
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a recording")
    got = report(tmp_path, str(directory), str(junk))["totals"]["provenance"]
    files = sum(len(run["files"]) for run in manifest["runs"])
    starts = [s for run in manifest["runs"] for s, _ in run["spans"]]
    ends = [e for run in manifest["runs"] for _, e in run["spans"]]
    local = lambda t: datetime.fromtimestamp(t, SITE_TZ).isoformat("T", "seconds")  # noqa: E731
    assert (got["files"], got["first"], got["last"]) == (
        files,
        local(min(starts)),
        local(max(ends)),
    )
    assert got["versions"] == {f"frog-bt {__version__}": files}
    ((tree, n),) = got["trees"].items()
    assert len(tree) == 12 and n == files
    assert got["configs"] == {fingerprint(load_site()): files}
    (skipped,) = got["skipped"]
    assert skipped.startswith(str(junk)) and len(skipped) > len(str(junk)) + 5  # and why


def test_the_configuration_hash_is_of_what_was_validated(tmp_path) -> None:
    """Comments and spacing do not change it; a value does."""
    text = (Path(__file__).resolve().parents[2] / "config" / "site.yaml").read_text()
    same, other = tmp_path / "same.yaml", tmp_path / "other.yaml"
    same.write_text("# a comment\n\n" + text)
    other.write_text(text.replace("language: es", "language: en"))
    assert "language: es" in text
    assert fingerprint(load_site(same)) == fingerprint(load_site())
    assert fingerprint(load_site(other)) != fingerprint(load_site())


def test_replay_of_the_season_reports_no_divergence(season, tmp_path) -> None:
    """Every tour of the season (a dock answered by hand, a home, a skip, an acknowledged
    alert, a restart and its resumed file) replays "identical": the staff's answers and
    the alert book are replayed with the tree, and the resumed executive starts from what
    it took up."""
    directory, manifest = season
    target = tmp_path / "replay.json"
    assert main(["replay", str(directory), "--quiet", "--jobs", "1", "--report", str(target)]) == 0
    rows = json.loads(target.read_text())["tours"]
    files = sum(len(run["files"]) for run in manifest["runs"])
    assert len(rows) == files and [r["status"] for r in rows] == ["identical"] * files
