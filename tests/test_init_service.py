"""``frog-bt init DIR --service``: a unit systemd accepts, run as a user that exists and
can write its folders. As root (CI), a real system user is created, checked by writing
as that user, and removed; elsewhere, what would be done is inspected."""

from __future__ import annotations

import os
import pwd
import shutil
import subprocess
import tempfile
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest

from frog_bt.cli import main
from frog_bt.commands.init import service_user

ROOT = os.geteuid() == 0


@pytest.fixture
def site() -> Iterator[Path]:
    """A site folder another user can reach (pytest's own temporary folders are not)."""
    top = Path(tempfile.mkdtemp(prefix="frog-bt-site-"))
    top.chmod(0o755)
    try:
        yield top / "frog"
    finally:
        shutil.rmtree(top)


def test_the_unit_passes_systemd_analyze_verify(site: Path) -> None:
    analyze = shutil.which("systemd-analyze")
    if analyze is None:
        pytest.skip("systemd-analyze is not installed (systemd)")
    me = pwd.getpwuid(os.geteuid()).pw_name
    assert main(["init", str(site), "--service", "--user", me]) == 0
    checked = subprocess.run(
        [analyze, "verify", str(site / "frog-bt.service")],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert checked.returncode == 0, checked.stderr
    assert f"User={me}\n" in (site / "frog-bt.service").read_text()


def test_what_would_be_done_for_a_user_that_does_not_exist(site: Path) -> None:
    plan = service_user(site, "frog", euid=1000, exists=lambda name: False)
    folder = site.resolve()
    assert not plan.exists and not plan.root
    assert plan.commands() == [
        f"useradd --system --user-group --no-create-home --home-dir {folder} "
        f"--shell {shutil.which('nologin') or '/usr/sbin/nologin'} frog",
        f"chown -R frog: {folder / 'state'} {folder / 'recordings'}",
    ]
    as_root = service_user(site, "frog", euid=0, exists=lambda name: True)
    assert as_root.root and as_root.commands() == [
        f"chown -R frog: {folder / 'state'} {folder / 'recordings'}"
    ]


def test_not_root_the_steps_are_printed(site: Path, capsys: pytest.CaptureFixture[str]) -> None:
    if ROOT:
        pytest.skip("as root init does them itself (the next test)")
    assert main(["init", str(site), "--service", "--user", "frog-no-such-user"]) == 0
    out = capsys.readouterr().out
    assert "sudo useradd --system" in out and "frog-no-such-user" in out
    assert f"sudo chown -R frog-no-such-user: {site.resolve() / 'state'}" in out


def test_as_root_the_user_is_created_and_can_write_its_folders(
    site: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if not ROOT or shutil.which("useradd") is None or shutil.which("runuser") is None:
        pytest.skip("needs root, useradd and runuser (CI runs as root)")
    name = f"frogbt-{uuid.uuid4().hex[:8]}"
    try:
        assert main(["init", str(site), "--service", "--user", name]) == 0
        out = capsys.readouterr().out
        entry = pwd.getpwnam(name)  # it exists now
        assert f"created the system user {name}" in out and "useradd" not in out
        assert entry.pw_uid < 1000  # a system user
        for folder in ("state", "recordings"):
            assert (site / folder).stat().st_uid == entry.pw_uid
            as_user = subprocess.run(
                ["runuser", "-u", name, "--", "touch", str(site / folder / "written")],
                capture_output=True,
                text=True,
                timeout=30,
                check=False,
            )
            assert as_user.returncode == 0, as_user.stderr
        reads = subprocess.run(
            ["runuser", "-u", name, "--", "cat", str(site / "config" / "site.yaml")],
            capture_output=True,
            timeout=30,
            check=False,
        )
        assert reads.returncode == 0
    finally:
        subprocess.run(["userdel", name], capture_output=True, timeout=30, check=False)
