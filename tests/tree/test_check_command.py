"""``frog-bt check``: every error of a tree in one pass, one ``file:line:column`` line
each, exit 2; the shipped tour and site pass with exit 0."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from frog_bt import resources
from frog_bt.cli import main


def test_the_shipped_tour_and_site_pass(capsys: pytest.CaptureFixture[str]) -> None:
    """Without the proof (tests/verify/test_verify.py: check with it, on the verdict the
    run explored once)."""
    assert main(["check", "--no-verify"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("ok: ") and "tour.yaml (" in out and "site.yaml" in out


def test_every_error_with_file_line_and_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    recruit = trees / "recruit.yaml"
    recruit.write_text(recruit.read_text().replace("      - {type: SeekVisitor}\n", ""))
    assert main(["check", str(trees / "tour.yaml")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1] == "frog-bt: 2 errors"
    found = [re.match(r"(.+):(\d+):(\d+): (\S+): (\w+) '", line) for line in lines[:-1]]
    assert all(found), lines
    assert [(Path(m[1]).name, int(m[2]), m[5]) for m in found if m] == [
        ("recruit.yaml", 17, "ApproachVisitor"),
        ("recruit.yaml", 30, "WaitAnswer"),
    ]


def test_a_bad_config_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site = tmp_path / "site.yaml"
    site.write_text(
        (resources.site_dir() / "site.yaml")
        .read_text()
        .replace("tick_hz:", "tick_hz: -1\n  old_tick_hz:", 1)
    )
    assert main(["check", "--config", str(site)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(site) in err


def test_structural_errors_all_at_once_sorted_by_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "root:\n  type: Sequence\n  memory: true\n  children:\n"
        "    - {type: Navigat, poi: POI1}\n"
        "    - {type: Navigate, poi: POI9}\n"
        "    - {type: Retry, attempts: 0, child: {type: GiveUp}}\n"
        "    - {type: Sequence, children: [{type: GiveUp}]}\n"
    )
    assert main(["check", str(bad)]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert lines == [
        f"{bad}:5:14: root.children[0].type: unknown type 'Navigat'; did you mean 'Navigate'?",
        f"{bad}:6:29: root.children[1].poi: unknown POI 'POI9' (known: END, POI0, POI1, POI1a, "
        "POI1b, POI2, POI2a, POI2b, POI3, POI4, POI5, SHOP, TEMP)",
        f"{bad}:7:31: root.children[2].attempts: Input should be greater than or equal to 1, got 0",
        f"{bad}:8:7: root.children[3].memory: missing required key: a Sequence must say "
        "memory: true or false",
        "frog-bt: 4 errors",
    ]


@pytest.mark.parametrize(
    ("file", "old", "new", "where"),
    [
        ("recruit.yaml", "      - {type: SeekVisitor}\n", "", "recruit.yaml:17:9:"),
        (
            "recruit.yaml",
            "      - {type: SeekVisitor}\n      - {type: ApproachVisitor}\n",
            "      - {type: ApproachVisitor}\n      - {type: SeekVisitor}\n",
            "recruit.yaml:17:9:",
        ),
        (
            "visit_poi.yaml",
            "                        "
            '- {type: DecideEngagement, about: "{poi}", when: face_stream}\n',
            "",
            "visit_poi.yaml:63:33:",
        ),
    ],
    ids=["no SeekVisitor", "SeekVisitor after ApproachVisitor", "no DecideEngagement at stops"],
)
def test_the_designers_mistakes_are_refused_with_file_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], file: str, old: str, new: str, where: str
) -> None:
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    path = trees / file
    assert old in path.read_text()
    path.write_text(path.read_text().replace(old, new))
    assert main(["check", str(trees / "tour.yaml")]) == 2
    first = capsys.readouterr().err.splitlines()[0]
    assert first.startswith(str(trees / where)), first
