"""Run the FROG executive against a robot's rosbridge and the content front end.

Loads and checks the site configuration and the tour tree, connects (reconnecting
for ever when a link drops), and ticks the tree until interrupted. With --once it
exits 0 after one tour has ended docked, and non-zero with a one-line reason when
it cannot go on.

Example, against the built-in simulator (frog-bt sim) on sim time:

  frog-bt run --sim-time --once
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import os
import signal
import sys
from pathlib import Path
from typing import Any

from frog_bt.clock import SimClock, WallClock
from frog_bt.config import Site, load_site, parse_hostport
from frog_bt.errors import DefinitionError
from frog_bt.tree.loader import DEFAULT_TREE, load_tree


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--config", type=Path, help="site configuration (default: config/site.yaml)")
    p.add_argument("--tree", type=Path, help=f"tour tree (default: {DEFAULT_TREE.name})")
    p.add_argument("--rosbridge", metavar="URL", help="rosbridge URL (default: from config, "
                   "ws://127.0.0.1:9090)")
    p.add_argument("--frontend", metavar="HOST:PORT",
                   help="where the front end listens (default: 127.0.0.1:5005)")
    p.add_argument("--listen", metavar="HOST:PORT",
                   help="where the executive listens for the front end (default: 127.0.0.1:5006)")
    p.add_argument("--sim-time", action="store_true",
                   help="take time from /clock (ROS use_sim_time); nothing is timed before it")
    p.add_argument("--record", metavar="FILE.mcap", type=Path,
                   help="record every message in and out to an MCAP file")
    p.add_argument("--rerun", metavar="SPEC",
                   help="rerun telemetry: spawn | save:FILE.rrd | connect:URL | serve "
                   "(default: off)")
    p.add_argument("--once", action="store_true",
                   help="exit 0 after one tour ends docked; non-zero when it cannot go on")
    p.add_argument("--checkpoint", type=Path, default=DEFAULT_CHECKPOINT, metavar="FILE",
                   help=f"tour progress, so that a restart resumes the tour (default: "
                   f"{DEFAULT_CHECKPOINT}); 'none' disables it")
    p.add_argument("--fresh", action="store_true",
                   help="ignore the checkpoint: start a fresh tour")
    p.add_argument("--quiet", action="store_true", help="no live status line")
    p.add_argument("-v", "--verbose", action="store_true", help="log at debug level")


DEFAULT_CHECKPOINT = Path(os.environ.get("XDG_STATE_HOME", Path.home() / ".local" / "state")
                          ) / "frog-bt" / "checkpoint.json"


def read_secret(site: Site) -> str | None:
    """The rosbridge auth secret: from the configured environment variable, else file."""
    links = site.links
    secret = os.environ.get(links.secret_env)
    if not secret and links.secret_file:
        secret = Path(links.secret_file).read_text(encoding="utf-8").strip()
    return secret or None


def attach_observers(executive: Any, *, record: Path | None, rerun: str | None) -> list[Any]:
    """Recorder and telemetry, each imported only when asked for; closed by the caller."""
    observers: list[Any] = []
    if record is not None:
        from frog_bt.recording import Recorder

        recorder = Recorder(record)
        recorder.attach(executive)
        observers.append(recorder)
    if rerun:
        from frog_bt.telemetry import Telemetry

        telemetry = Telemetry.open(rerun, executive.site, executive.core.tree)
        telemetry.attach(executive.core)
        observers.append(telemetry)
    return observers


def run(args: argparse.Namespace) -> int:
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        site = load_site(args.config)
        tree = load_tree(args.tree, site)
        frontend = parse_hostport(args.frontend or site.links.frontend, "--frontend")
        listen = parse_hostport(args.listen or site.links.listen, "--listen")
        secret = read_secret(site)
    except (DefinitionError, ValueError, OSError) as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    from frog_bt.executive import Executive  # the network stack only when running
    from frog_bt.status import StatusLine

    clock = SimClock() if args.sim_time else WallClock()

    async def main() -> int:
        url = args.rosbridge or site.links.rosbridge
        executive = Executive(site, tree, clock, rosbridge_url=url, frontend=frontend,
                              listen=listen, sim_time=args.sim_time, secret=secret,
                              once=args.once, fresh=args.fresh,
                              checkpoint=None if str(args.checkpoint) == "none"
                              else args.checkpoint)
        loop = asyncio.get_running_loop()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, executive.stop, f"stopped by {sig.name}", 0)
        status = None if args.quiet else StatusLine()
        if status is not None:
            executive.taps.tick.append(status.update)
        observers = attach_observers(executive, record=args.record, rerun=args.rerun)
        try:
            outcome = await executive.run()
        finally:
            for observer in observers:
                observer.close()
            if status is not None:
                status.close()
        if outcome.code:
            print(f"frog-bt: {outcome.reason}", file=sys.stderr)
        return outcome.code

    try:
        return asyncio.run(main())
    except OSError as exc:  # e.g. the listen port is taken
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 1
