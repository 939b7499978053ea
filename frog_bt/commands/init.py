"""Write an editable copy of the tour tree files and the site configuration.

For a new site, or to change the tour on an installed robot without touching
Python: DIR/trees/*.yaml (tour.yaml and the files it includes) and
DIR/config/site.yaml, copied from the packaged ones. Then:

  frog-bt check/render/run/demo --tree DIR/trees/tour.yaml --config DIR/config/site.yaml

Existing files are left alone unless --force. With --service, also DIR/frog-bt.service:
a systemd unit (Type=notify, a watchdog, Restart=always) that runs the executive with
that folder's files as an ordinary user; it prints how to install it (docs/DEPLOY.md).
"""

from __future__ import annotations

import argparse
import shutil
import sys
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


def unit_text(target: Path, user: str | None = None) -> str:
    """The systemd unit for a site folder (absolute paths; no root at run time)."""
    import getpass
    import os
    import shutil as sh

    folder = target.resolve()
    exe = sh.which("frog-bt") or str(Path(sys.argv[0]).resolve())
    if user is None:
        user = "frog" if os.geteuid() == 0 else getpass.getuser()
    return UNIT.format(unit=folder / "frog-bt.service", user=user, dir=folder, exe=exe)


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
    try:
        for src, dst in plan:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(src, dst)
        if args.service:
            for folder in ("state", "recordings"):
                (args.dir / folder).mkdir(exist_ok=True)
            service.write_text(unit_text(args.dir, args.user), encoding="utf-8")
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
        print(
            f"wrote {service}\n\nInstall the service (it runs as an ordinary user):\n"
            f"  sudo cp {service.resolve()} /etc/systemd/system/\n"
            "  sudo systemctl daemon-reload && sudo systemctl enable --now frog-bt\n"
            "  journalctl -u frog-bt -f"
        )
    return 0
