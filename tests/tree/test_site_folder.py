"""Every command finds a site folder made by ``frog-bt init`` before the packaged files,
from the working directory up (as git finds its repository), and says which files."""

from __future__ import annotations

from pathlib import Path

import pytest

from frog_bt.cli import main


def test_check_in_a_folder_made_by_init_checks_that_folders_files(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    site = tmp_path / "alcazar"
    assert main(["init", str(site)]) == 0
    recruit = site / "trees" / "recruit.yaml"
    recruit.write_text(recruit.read_text().replace("      - {type: SeekVisitor}\n", ""))
    capsys.readouterr()
    (site / "notes").mkdir()
    for where in (site, site / "notes"):  # the folder itself, and below it
        monkeypatch.chdir(where)
        assert main(["check"]) == 2
        err = capsys.readouterr().err
        assert err.splitlines()[0] == (
            f"frog-bt: site folder {site}: using {site / 'trees' / 'tour.yaml'}, "
            f"{site / 'config' / 'site.yaml'}"
        )
        assert f"{recruit}:17:9: root.child.children[0]: ApproachVisitor" in err


def test_an_option_given_wins_and_elsewhere_the_packaged_files_are_used(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    site = tmp_path / "alcazar"
    assert main(["init", str(site)]) == 0
    (site / "config" / "site.yaml").write_text("pois: nope\n")  # broken: must not be read
    monkeypatch.chdir(site)
    capsys.readouterr()
    packaged_config = Path(__file__).resolve().parents[2] / "config" / "site.yaml"
    assert main(["check", "--no-verify", "--config", str(packaged_config)]) == 0
    out = capsys.readouterr()
    assert "using " + str(site / "trees" / "tour.yaml") in out.err  # the tree: the folder's
    assert out.out.startswith(f"ok: {site / 'trees' / 'tour.yaml'}")
    empty = tmp_path / "elsewhere"
    empty.mkdir()
    monkeypatch.chdir(empty)
    assert main(["check", "--no-verify"]) == 0
    out = capsys.readouterr()
    assert out.err == "" and out.out.startswith("ok: ")
