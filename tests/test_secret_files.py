"""Files only their owner reads: a recording is 0640 (even over an older file), and
``check`` says in one line when a secret sits in a file others can read."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from frog_bt import resources
from frog_bt.cli import main
from frog_bt.live.recording import Recorder


def test_a_recording_is_for_its_owner_and_group(tmp_path: Path) -> None:
    path = tmp_path / "tour.mcap"
    path.write_bytes(b"")
    path.chmod(0o666)  # a file left there before
    with Recorder(path):
        pass
    assert path.stat().st_mode & 0o777 == 0o640


def test_check_warns_in_one_line_about_webhook_credentials_others_can_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "site.yaml"
    shutil.copyfile(resources.site_dir() / resources.SITE_FILE, config)
    tree = str(resources.tree_dir() / resources.TREE_FILE)

    def warnings(mode: int) -> list[str]:
        config.chmod(mode)
        assert main(["check", tree, "--config", str(config), "--no-verify"]) == 0
        return [line for line in capsys.readouterr().err.splitlines() if "warning" in line]

    assert warnings(0o644) == []  # no secret in it
    with config.open("a") as f:
        f.write("alerts:\n  webhooks:\n    - https://frog:s3cret@hooks.example/x\n")
    assert warnings(0o600) == []
    assert warnings(0o644) == [
        f"frog-bt: warning: {config}: holds webhook credentials and others than its owner "
        f"can read it; fix: chmod 600 {config}"
    ]
    assert all("s3cret" not in line for line in warnings(0o640))
