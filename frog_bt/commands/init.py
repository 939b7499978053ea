"""Write an editable copy of the tour tree files and the site configuration.

For a new site, or to change the tour on an installed robot without touching
Python: DIR/trees/*.yaml (tour.yaml and the files it includes) and
DIR/config/site.yaml, copied from the packaged ones. Then:

  frog-bt check/render/run/demo --tree DIR/trees/tour.yaml --config DIR/config/site.yaml

Existing files are left alone unless --force. With --service, also DIR/frog-bt.service:
a systemd unit (Type=notify, a watchdog, Restart=always) that runs the executive with
that folder's files as an ordinary user, and DIR/state/ and DIR/recordings/ for it to
write. Run as root, it creates that user when there is none (``useradd --system``;
where it cannot, it prints the one command that does) and gives it those two folders;
it prints how to install the unit (docs/DEPLOY.md).
"""

from __future__ import annotations

import argparse
import os
import pwd
import shlex
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from frog_bt import resources


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", type=Path, metavar="DIR", help="where to write trees/ and config/")
    p.add_argument("--force", action="store_true", help="overwrite files that exist")
    p.add_argument(
        "--service",
        action="store_true",
        help="also write DIR/frog-bt.service, a systemd unit for the executive",
    )
    p.add_argument(
        "--user",
        default=None,
        help="the user the service runs as (default: you; 'frog' when you are "
        "root: the executive needs no root)",
    )


UNIT = """\
# frog-bt: the FROG tour executive as a systemd service (written by frog-bt init --service)
# Install:  sudo cp {unit} /etc/systemd/system/ && sudo systemctl daemon-reload
#           sudo systemctl enable --now frog-bt
# Logs:     journalctl -u frog-bt -f        (levels: journalctl -u frog-bt -p warning)
[Unit]
Description=FROG tour robot executive (frog-bt)
Wants=network-online.target
After=network-online.target

[Service]
Type=notify
NotifyAccess=main
User={user}
WorkingDirectory={dir}
ExecStart={exe} run --quiet --tree {dir}/trees/tour.yaml --config {dir}/config/site.yaml \\
    --checkpoint {dir}/state/checkpoint.json --record {dir}/recordings
# The executive pings the watchdog from its tick loop: a wedged loop is restarted, and the
# checkpoint resumes the tour.
WatchdogSec=10
Restart=always
RestartSec=2
TimeoutStopSec=10
Environment=PYTHONUNBUFFERED=1

[Install]
WantedBy=multi-user.target
"""


def default_user() -> str:
    """You; ``frog`` when you are root (the executive needs no root)."""
    import getpass

    return "frog" if os.geteuid() == 0 else getpass.getuser()


def unit_text(target: Path, user: str | None = None) -> str:
    """The systemd unit for a site folder (absolute paths; no root at run time)."""
    folder = target.resolve()
    beside = Path(sys.executable).parent / "frog-bt"  # this installation's, first
    exe = (
        str(beside)
        if beside.is_file()
        else shutil.which("frog-bt") or str(Path(sys.argv[0]).resolve())
    )
    user = user or default_user()
    return UNIT.format(unit=folder / "frog-bt.service", user=user, dir=folder, exe=exe)


SERVICE_FOLDERS = ("state", "recordings")  # what the unit's user writes


@dataclass(frozen=True, slots=True)
class ServiceUser:
    """What ``init --service`` does about the unit's user: create it (``create``, the
    command), then give it ``folders`` (``chown``); ``exists`` when it already does."""

    name: str
    exists: bool
    create: tuple[str, ...]
    folders: tuple[Path, ...]
    root: bool  # run as root: it does these itself; else it says them

    def commands(self) -> list[str]:
        """The shell commands that do it by hand (as root)."""
        out = [] if self.exists else [shlex.join(self.create)]
        if self.folders:
            out.append(shlex.join(["chown", "-R", f"{self.name}:", *map(str, self.folders)]))
        return out


def service_user(
    target: Path,
    user: str,
    *,
    euid: int | None = None,
    exists: Callable[[str], bool] | None = None,
) -> ServiceUser:
    """The plan for ``user`` (inspected by tests without creating anyone)."""
    euid = os.geteuid() if euid is None else euid
    known = (exists or _user_exists)(user)
    nologin = shutil.which("nologin") or "/usr/sbin/nologin"
    create = (
        "useradd", "--system", "--user-group", "--no-create-home",
        "--home-dir", str(target.resolve()), "--shell", nologin, user,
    )  # fmt: skip
    mine = known and euid != 0 and pwd.getpwnam(user).pw_uid == euid
    folders = () if mine else tuple(target.resolve() / f for f in SERVICE_FOLDERS)
    return ServiceUser(user, known, create, folders, root=euid == 0)


def _user_exists(name: str) -> bool:
    try:
        pwd.getpwnam(name)
    except KeyError:
        return False
    return True


def give_folders(plan: ServiceUser) -> list[str]:
    """As root: create the user when it can and give it the folders; what is left for a
    person to do, as commands (empty when done)."""
    if not plan.root:
        return plan.commands()
    if not plan.exists:
        if shutil.which(plan.create[0]) is None:
            return plan.commands()
        done = subprocess.run(plan.create, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            why = (done.stderr or done.stdout).strip().splitlines()
            print(f"frog-bt: {shlex.join(plan.create)}: {why[-1] if why else done.returncode}")
            return plan.commands()
        print(f"created the system user {plan.name}")
    entry = pwd.getpwnam(plan.name)
    for folder in plan.folders:
        for place in (folder, *folder.rglob("*")):
            os.chown(place, entry.pw_uid, entry.pw_gid)
        folder.chmod(0o750)
    if plan.folders:
        print(f"gave {', '.join(str(f) for f in plan.folders)} to {plan.name}")
        closed = _closed_to(plan.folders[0].parent, entry.pw_uid, entry.pw_gid)
        if closed is not None:
            return [f"chmod o+x {shlex.quote(str(closed))}"]
    return []


def _closed_to(folder: Path, uid: int, gid: int) -> Path | None:
    """The first folder on the way to ``folder`` that the user cannot pass, if any."""
    for place in (*reversed(folder.parents), folder):
        st = place.stat()
        who = 6 if st.st_uid == uid else 3 if st.st_gid == gid else 0
        if not (st.st_mode >> who) & 0o1:
            return place
    return None


def copies(target: Path) -> list[tuple[Path, Path]]:
    """(packaged file, where it goes) for every file ``init`` writes."""
    out = [
        (src, target / "trees" / src.name)
        for src in sorted(
            [*resources.tree_dir().glob("*.yaml"), *resources.tree_dir().glob("*.schema.json")]
        )
    ]
    for src in (
        resources.site_dir() / resources.SITE_FILE,
        *resources.site_dir().glob("*.schema.json"),
    ):
        out.append((src, target / "config" / src.name))
    return out


def run(args: argparse.Namespace) -> int:
    plan = copies(args.dir)
    if not args.force:
        existing = [dst for _, dst in plan if dst.exists()]
        if existing:
            print(
                f"frog-bt: {existing[0]}: exists; give --force to overwrite "
                f"({len(existing)} file{'s' if len(existing) > 1 else ''} would be)",
                file=sys.stderr,
            )
            return 2
    service = args.dir / "frog-bt.service"
    if args.service and service.exists() and not args.force:
        print(f"frog-bt: {service}: exists; give --force to overwrite", file=sys.stderr)
        return 2
    user = args.user or default_user()
    todo: list[str] = []
    try:
        for src, dst in plan:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
        if args.service:
            for folder in SERVICE_FOLDERS:
                (args.dir / folder).mkdir(exist_ok=True)
            service.write_text(unit_text(args.dir, user), encoding="utf-8")
            todo = give_folders(service_user(args.dir, user))
    except OSError as exc:
        where = exc.filename or args.dir
        print(f"frog-bt: {where}: cannot write: {exc.strerror or exc}", file=sys.stderr)
        return 2
    for _, dst in plan:
        print(f"wrote {dst}")
    tree, site = args.dir / "trees" / resources.TREE_FILE, args.dir / "config" / resources.SITE_FILE
    print(
        f"\nEdit them, then:\n  frog-bt render --tree {tree} --config {site}\n"
        f"  frog-bt demo --tree {tree} --config {site}\n"
        f"  frog-bt run --tree {tree} --config {site} ..."
    )
    if args.service:
        if todo:
            sudo = "" if os.geteuid() == 0 else "sudo "
            steps = "\n".join(f"  {sudo}{c}" for c in todo)
            print(f"\nThe service runs as {user}, who must exist and own its folders:\n{steps}")
        print(
            f"wrote {service}\n\nInstall the service (it runs as {user}, not root):\n"
            f"  sudo cp {service.resolve()} /etc/systemd/system/\n"
            "  sudo systemctl daemon-reload && sudo systemctl enable --now frog-bt\n"
            "  journalctl -u frog-bt -f"
        )
    return 0
