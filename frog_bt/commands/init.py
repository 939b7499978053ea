"""Write an editable copy of the tour tree files and the site configuration.

For a new site, or to change the tour on an installed robot without touching
Python: DIR/trees/*.yaml (tour.yaml and the files it includes) and
DIR/config/site.yaml, copied from the packaged ones. Then:

  frog-bt check/render/run/demo --tree DIR/trees/tour.yaml --config DIR/config/site.yaml

Existing files are left alone unless --force; the site configuration is written 0600
(webhook credentials go there). With --service, also DIR/frog-bt.service: a systemd unit
(Type=notify, a watchdog, Restart=always, sandboxed as systemd recommends for a network
daemon) that runs the executive with that folder's files as an ordinary user, its
console on loopback with DIR/console-token (a random token, 0600, handed over with
LoadCredential=), and DIR/state/ and DIR/recordings/ for it to write. It says in one
line when that user cannot read or run the unit's program. Run as root, it creates
that user when there is none (``useradd --system``; where it cannot, it prints the one
command that does) and gives it those two folders and the site configuration; it prints
how to install the unit (docs/DEPLOY.md).
"""

from __future__ import annotations

import argparse
import os
import pwd
import secrets
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
# Sandbox:  systemd-analyze security frog-bt (docs/DEPLOY.md: what each line is for)
[Unit]
Description=FROG tour robot executive (frog-bt)
Wants=network-online.target
After=network-online.target

[Service]
Type=notify
NotifyAccess=main
User={user}
WorkingDirectory={dir}
# the console's token, handed over by systemd (read as root, shown to the service only)
LoadCredential=console-token:{dir}/console-token
ExecStart={exe} run --quiet --tree {dir}/trees/tour.yaml --config {dir}/config/site.yaml \\
    --checkpoint {dir}/state/checkpoint.json --record {dir}/recordings \\
    --console 127.0.0.1:8080 --console-token-file %d/console-token
# The executive pings the watchdog from its tick loop: a wedged loop is restarted, and the
# checkpoint resumes the tour.
WatchdogSec=10
Restart=always
RestartSec=2
TimeoutStopSec=10
Environment=PYTHONUNBUFFERED=1
UMask=0027
# The sandbox: it writes only its state and recordings, talks only IP (and to systemd
# over a Unix socket), holds no capability and makes only a service's system calls.
NoNewPrivileges=yes
ProtectSystem=strict
ReadWritePaths={dir}/state {dir}/recordings
ProtectHome={protect_home}
PrivateTmp=yes
PrivateDevices=yes
PrivateMounts=yes
PrivateUsers=yes
ProtectKernelTunables=yes
ProtectKernelModules=yes
ProtectKernelLogs=yes
ProtectControlGroups=yes
ProtectClock=yes
ProtectHostname=yes
ProtectProc=invisible
RestrictAddressFamilies=AF_INET AF_INET6 AF_UNIX
RestrictNamespaces=yes
RestrictRealtime=yes
RestrictSUIDSGID=yes
LockPersonality=yes
MemoryDenyWriteExecute=yes
RemoveIPC=yes
CapabilityBoundingSet=
AmbientCapabilities=
SystemCallArchitectures=native
SystemCallFilter=@system-service
SystemCallFilter=~@privileged
SystemCallErrorNumber=EPERM

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
    # a site folder or an installation under /home or /root stays readable (not writable)
    homes = ("/home", "/root", "/run/user")
    under_home = any(str(p).startswith(homes) for p in (folder, Path(exe)))
    return UNIT.format(
        unit=folder / "frog-bt.service",
        user=user,
        dir=folder,
        exe=exe,
        protect_home="read-only" if under_home else "yes",
    )


def service_exe(unit: str) -> Path:
    """The program a unit's ``ExecStart`` runs."""
    line = next(x for x in unit.splitlines() if x.startswith("ExecStart="))
    return Path(line.removeprefix("ExecStart=").split()[0])


def cannot_run(exe: Path, uid: int, gid: int) -> str | None:
    """Why the user ``uid``:``gid`` cannot read and run ``exe`` and the interpreter its
    ``#!`` line names (a virtual environment under /root, say), or None when it can."""
    programs = [exe]
    try:
        with exe.open("rb") as f:
            first = f.readline(512)
        if first.startswith(b"#!"):
            programs.append(Path(first[2:].decode("utf-8", "replace").split()[0]))
    except (OSError, IndexError):
        pass
    for program in programs:
        for place in (*reversed(program.parents), program):
            try:
                st = place.stat()
            except OSError as exc:
                return f"{place}: {exc.strerror or exc}"
            who = 6 if st.st_uid == uid else 3 if st.st_gid == gid else 0
            need = 0o1 if place != program else 0o5  # pass folders; read and run the file
            if uid != 0 and (st.st_mode >> who) & need != need:
                return f"{place} is closed to it" if place != program else f"it cannot run {place}"
    return None


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
    private: tuple[Path, ...] = ()  # files only it reads (0600): the site configuration

    def commands(self) -> list[str]:
        """The shell commands that do it by hand (as root)."""
        out = [] if self.exists else [shlex.join(self.create)]
        if self.folders:
            out.append(shlex.join(["chown", "-R", f"{self.name}:", *map(str, self.folders)]))
        if self.private:
            out.append(shlex.join(["chown", f"{self.name}:", *map(str, self.private)]))
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
    private = () if mine else (target.resolve() / "config" / resources.SITE_FILE,)
    return ServiceUser(user, known, create, folders, root=euid == 0, private=private)


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
    for private in plan.private:
        os.chown(private, entry.pw_uid, entry.pw_gid)
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


TOKEN_FILE = "console-token"  # beside the unit: LoadCredential= hands it to the service
PRIVATE = 0o600


def write_token(path: Path) -> bool:
    """A new random console token in ``path`` (0600), unless one is there; whether one was
    written."""
    if path.exists():
        return False
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, PRIVATE)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(secrets.token_urlsafe(32) + "\n")
    return True


def _cannot_run_as(user: str, exe: Path) -> str | None:
    """One line when ``user`` (if it exists) cannot read and run the unit's program."""
    try:
        entry = pwd.getpwnam(user)
    except KeyError:
        return None
    why = cannot_run(exe, entry.pw_uid, entry.pw_gid)
    if why is None:
        return None
    return (
        f"the service user {user} cannot run {exe} ({why}): install frog-bt where {user} "
        "can read it, e.g. python3 -m venv /opt/frog-bt (docs/DEPLOY.md)"
    )


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
    wrote_token, closed = False, None
    try:
        for src, dst in plan:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
        site_file = args.dir / "config" / resources.SITE_FILE
        site_file.chmod(PRIVATE)  # where webhook credentials go: its owner's only
        if args.service:
            for folder in SERVICE_FOLDERS:
                (args.dir / folder).mkdir(exist_ok=True)
            unit = unit_text(args.dir, user)
            service.write_text(unit, encoding="utf-8")
            wrote_token = write_token(args.dir / TOKEN_FILE)
            todo = give_folders(service_user(args.dir, user))
            closed = _cannot_run_as(user, service_exe(unit))
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
        if wrote_token:
            print(
                f"wrote {args.dir / TOKEN_FILE} (the console's token, 0600: for ctl --token-file)"
            )
        if closed:
            print(f"frog-bt: warning: {closed}")
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
