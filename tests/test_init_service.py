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
        f"chown frog: {folder / 'config' / 'site.yaml'}",  # 0600: the service reads it
    ]
    as_root = service_user(site, "frog", euid=0, exists=lambda name: True)
    assert as_root.root and as_root.commands() == [
        f"chown -R frog: {folder / 'state'} {folder / 'recordings'}",
        f"chown frog: {folder / 'config' / 'site.yaml'}",
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


def test_the_unit_is_sandboxed_and_scored(site: Path) -> None:
    """The hardening systemd recommends for a network daemon, the token as a credential,
    and the score docs/DEPLOY.md gives (``systemd-analyze security``, where installed)."""
    user = "daemon" if _exists("daemon") else pwd.getpwuid(os.geteuid()).pw_name
    assert main(["init", str(site), "--service", "--user", user]) == 0
    unit = (site / "frog-bt.service").read_text()
    folder = site.resolve()
    for line in (
        "NoNewPrivileges=yes",
        "ProtectSystem=strict",
        f"ReadWritePaths={folder}/state {folder}/recordings",
        "PrivateTmp=yes",
        "RestrictAddressFamilies=AF_INET AF_INET6 AF_UNIX",
        "CapabilityBoundingSet=",
        "SystemCallFilter=@system-service",
        f"LoadCredential=console-token:{folder}/console-token",
    ):
        assert f"\n{line}\n" in unit, line
    assert "\nProtectHome=yes\n" in unit  # the site folder is not under /home
    assert "--console 127.0.0.1:8080 --console-token-file %d/console-token" in unit
    analyze = shutil.which("systemd-analyze")
    if analyze is None:
        pytest.skip("systemd-analyze is not installed (systemd)")
    scored = subprocess.run(
        [analyze, "security", "--offline=yes", str(site / "frog-bt.service")],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    if user == "root":
        pytest.skip("scored as root: the score counts the user")
    last = scored.stdout.strip().splitlines()[-1]
    assert "Overall exposure level for frog-bt.service: 1.2 OK" in last, scored.stdout[-500:]


def test_secrets_are_written_for_their_owner_only(site: Path) -> None:
    me = pwd.getpwuid(os.geteuid()).pw_name
    assert main(["init", str(site), "--service", "--user", me]) == 0
    token = site / "console-token"
    assert token.stat().st_mode & 0o777 == 0o600 and len(token.read_text().strip()) >= 32
    assert (site / "config" / "site.yaml").stat().st_mode & 0o777 == 0o600
    before = token.read_text()
    assert main(["init", str(site), "--service", "--user", me, "--force"]) == 0
    assert token.read_text() == before  # a token there is kept


def test_a_program_the_service_user_cannot_run_is_said_in_one_line(
    site: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from frog_bt.commands.init import cannot_run

    home = site.parent / "root-home"
    venv = home / "venv" / "bin"
    venv.mkdir(parents=True)
    exe = venv / "frog-bt"
    exe.write_text(f"#!{venv / 'python'}\n")
    exe.chmod(0o755)
    (venv / "python").write_text("")
    (venv / "python").chmod(0o755)
    home.chmod(0o700)  # as /root
    stranger = 65534  # nobody
    assert cannot_run(exe, stranger, stranger) == f"{home} is closed to it"
    home.chmod(0o755)
    assert cannot_run(exe, stranger, stranger) is None
    (venv / "python").chmod(0o700)
    assert cannot_run(exe, stranger, stranger) == f"it cannot run {venv / 'python'}"
    if ROOT:  # the line init prints, for a user that exists
        home.chmod(0o700)
        from frog_bt.commands import init

        line = init._cannot_run_as("nobody", exe)
        assert line is not None and "\n" not in line
        assert line.startswith(f"the service user nobody cannot run {exe} ({home} is closed")


def _exists(name: str) -> bool:
    try:
        pwd.getpwnam(name)
    except KeyError:
        return False
    return True
