"""Run the FROG executive against a robot's rosbridge and the content front end.

Loads and checks the site configuration and the tour tree, connects (reconnecting
for ever when a link drops), and ticks the tree until interrupted. With --once it
exits 0 after one tour has ended docked, and non-zero with a one-line reason when
it cannot go on.

Example, against the built-in simulator (frog-bt sim) on sim time:

  frog-bt run --sim-time --once

Every option may also come from the environment (FROG_BT_ROSBRIDGE=ws://frog:9090,
FROG_BT_SIM_TIME=1, FROG_BT_CONSOLE=8080, ...: FROG_BT_ and the option's name) or from
the site configuration's run: section (run: {rosbridge: ws://frog:9090, quiet: true}).
The command line wins, then the environment, then run:, then the defaults below.
--tree and --config may come from FROG_BT_TREE and FROG_BT_CONFIG.
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import logging
import os
import signal
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from frog_bt import __version__, resources
from frog_bt.behaviours import load_tree
from frog_bt.clock import Clock, SimClock, WallClock
from frog_bt.commands import logs
from frog_bt.commands.console_options import (
    ConsoleSettings,
    add_console_arguments,
    console_settings,
    start_people,
)
from frog_bt.commands.exposed import exposed
from frog_bt.commands.options import add_tree_and_config, read_secret, rerun_spec, writable_file
from frog_bt.commands.settings import fill, tree_and_config
from frog_bt.config import DEFAULT_CONFIG, Site, check_ws_url, load_site, parse_hostport
from frog_bt.errors import FrogError, UsageError, error_lines
from frog_bt.frontend.link import AddressError
from frog_bt.runtime.checkpoint import STATE_DIR
from frog_bt.runtime.checkpoint import claim as claim_checkpoint
from frog_bt.runtime.checkpoint import default_path as default_checkpoint
from frog_bt.runtime.observer import Observer, attach_all, close_all
from frog_bt.tree.loader import DEFAULT_TREE

if TYPE_CHECKING:
    from frog_bt.runtime.executive import Executive


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_and_config(p)
    p.add_argument(
        "--rosbridge",
        metavar="URL",
        help="rosbridge URL (default: from config, ws://127.0.0.1:9090)",
    )
    p.add_argument(
        "--frontend",
        metavar="HOST:PORT",
        help="where the front end listens (default: 127.0.0.1:5005)",
    )
    p.add_argument(
        "--listen",
        metavar="HOST:PORT",
        help="where the executive listens for the front end (default: 127.0.0.1:5006)",
    )
    p.add_argument(
        "--sim-time",
        action="store_true",
        default=None,
        help="take time from /clock (ROS use_sim_time); nothing is timed before it",
    )
    p.add_argument(
        "--record",
        metavar="FILE.mcap|DIR",
        type=Path,
        help="record every message in and out: to one MCAP file (FILE.mcap), or "
        "to DIR, one file per tour and idle period within the site config's "
        "recording.max_bytes (oldest deleted first)",
    )
    p.add_argument(
        "--rerun",
        metavar="SPEC",
        help="rerun telemetry: spawn | save:FILE.rrd | connect:URL | serve (default: off)",
    )
    p.add_argument(
        "--once",
        action="store_true",
        default=None,
        help="exit 0 after one tour ends docked; non-zero when it cannot go on",
    )
    p.add_argument(
        "--checkpoint",
        type=Path,
        metavar="FILE",
        help=f"tour progress, so that a restart resumes the tour (default: one file "
        f"per site config and listen address in {STATE_DIR}); 'none' disables it",
    )
    p.add_argument(
        "--fresh",
        action="store_true",
        default=None,
        help="ignore the checkpoint: start a fresh tour",
    )
    p.add_argument(
        "--watch",
        action="store_true",
        default=None,
        help="re-check the tree and config files when they change; a valid change "
        "takes over when the robot is docked and idle, a bad one is reported and "
        "the running tree stays",
    )
    add_console_arguments(p)
    p.add_argument("--quiet", action="store_true", default=None, help="no live status line")
    p.add_argument("-v", "--verbose", action="store_true", help="log at debug level")
    p.add_argument(
        "--log-format",
        choices=("text", "json"),
        default=None,
        help="text (levels as syslog prefixes under systemd) or one JSON object "
        "per line (default: text)",
    )


@dataclass(frozen=True, slots=True)
class Settings:
    """Everything ``run`` resolved and checked from its options and the site config."""

    url: str
    frontend: tuple[str, int]
    listen: tuple[str, int]
    checkpoint: Path | None
    record: Path | None
    rerun: str | None
    secret: str | None


def resolve(args: argparse.Namespace, site: Site) -> Settings:
    """Check every option against the site config's defaults; UsageError on the first bad one."""
    listen = parse_hostport(_given(args.listen, site.links.listen), "--listen")
    checkpoint = args.checkpoint
    if checkpoint is None:
        checkpoint = default_checkpoint(Path(args.config or DEFAULT_CONFIG), listen)
    elif str(checkpoint) == "none":
        checkpoint = None
    elif checkpoint.is_dir():
        raise UsageError("--checkpoint", checkpoint, "is a directory; expected a file path")
    return Settings(
        url=check_ws_url(_given(args.rosbridge, site.links.rosbridge), "--rosbridge"),
        frontend=parse_hostport(_given(args.frontend, site.links.frontend), "--frontend"),
        listen=listen,
        checkpoint=checkpoint,
        record=None if args.record is None else record_target(args.record),
        rerun=rerun_spec(args.rerun),
        secret=read_secret(site),
    )


def _given(value: str | None, default: str) -> str:
    """An option's value, or the site config's when the option is not given at all (an
    empty value is given, and refused like any bad one: not quietly the default)."""
    return default if value is None else value


def record_target(path: Path) -> Path:
    """``--record``: a ``.mcap`` file (CONTRACT §6), else a directory (created if missing,
    in an existing folder)."""
    if path.suffix == ".mcap" and not path.is_dir():
        return writable_file(path, "--record")
    if path.exists() and not path.is_dir():
        raise UsageError(
            "--record", path, "is a file but not .mcap; expected FILE.mcap or a directory"
        )
    parent = path.parent if not path.exists() else path
    if not parent.is_dir():
        raise UsageError("--record", path, f"cannot write there: {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise UsageError("--record", path, "cannot write there: permission denied")
    return path


def banner(args: argparse.Namespace, settings: Settings) -> list[str]:
    """What this executive runs and where it talks, for the first lines of its output."""

    def shown(path: Path | None) -> str:
        return str(path) if path is not None else "off"

    return [
        f"frog-bt {__version__}: tree {args.tree or DEFAULT_TREE}, "
        f"config {args.config or DEFAULT_CONFIG}",
        f"  clock {'sim time (/clock)' if args.sim_time else 'wall clock'}; "
        f"rosbridge {settings.url}{' (auth)' if settings.secret else ''}; "
        "front end {}:{}; listening on {}:{}".format(*settings.frontend, *settings.listen),
        f"  checkpoint {shown(settings.checkpoint)}; recording {shown(settings.record)}; "
        f"telemetry {settings.rerun or 'off'}",
    ]


__all__ = ["add_arguments", "attach_observers", "build", "read_secret", "run"]


def attach_observers(
    executive: Executive, *, record: Path | None, rerun: str | None
) -> list[Observer]:
    """Recorder and telemetry, each imported only when asked for, attached; the caller
    closes them (:func:`~frog_bt.runtime.observer.close_all`)."""
    observers: list[Observer] = []
    if record is not None and record.suffix == ".mcap" and not record.is_dir():
        from frog_bt.live.recording import Recorder

        observers.append(Recorder(record))
    elif record is not None:
        from frog_bt.live.rotation import RecordingDir

        observers.append(RecordingDir(record, executive.site.recording.max_bytes))
    if rerun:
        from frog_bt.live.telemetry import Telemetry, process

        if process.available():  # rerun in a process of its own: off the tick, its memory
            observers.append(process.TelemetryProcess(rerun, executive.site, executive.core.tree))
        else:
            observers.append(Telemetry.open(rerun, executive.site, executive.core.tree))
    return attach_all(executive, observers)


def run(args: argparse.Namespace) -> int:
    from frog_bt.runtime import memory

    collecting = gc.isenabled()
    memory.hold_collector()  # loading the site and the tree: nothing to free (memory.py)
    tree_and_config(args)
    logs.setup(args.verbose, os.environ.get("FROG_BT_LOG_FORMAT") or args.log_format or "text")
    try:
        site = load_site(args.config)
        fill(args, site.run)
        logs.setup(args.verbose, args.log_format)  # run: may have chosen it
        tree = load_tree(args.tree, site)
        settings = resolve(args, site)
        console = console_settings(args)
        lock = claim_checkpoint(settings.checkpoint) if settings.checkpoint else None
    except FrogError as exc:
        if collecting:
            gc.enable()
        for line in error_lines(exc):
            print(f"frog-bt: {line}", file=sys.stderr)
        return 2
    print("\n".join(banner(args, settings)), flush=True)
    config = Path(args.config) if args.config else resources.site_dir() / resources.SITE_FILE
    for line in exposed(config, site):
        logging.getLogger("frog_bt").warning("%s", line)
    # What start-up built lives all day: frozen, later full collections skip it; the
    # collector is on again from here.
    memory.freeze_heap()
    try:
        return asyncio.run(_main(args, site, tree, settings, console))
    except AddressError as exc:  # the listen port is taken, the front end's host unknown
        option = "--listen" if exc.which == "listen" else "--frontend"
        print(f"frog-bt: {option} {exc}", file=sys.stderr)
        return 2
    except UsageError as exc:  # the console's port is taken
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    finally:
        if lock is not None:
            lock.close()


async def _main(
    args: argparse.Namespace,
    site: Site,
    tree: Any,
    settings: Settings,
    console: ConsoleSettings | None = None,
) -> int:
    from frog_bt.runtime.memory import HeapKeeper, QuietCollector, pin_malloc_thresholds

    pin_malloc_thresholds()  # all day without creeping up
    from frog_bt.runtime.exits import ExitRules
    from frog_bt.runtime.keeper import Keeper
    from frog_bt.runtime.status import StatusLine

    clock = SimClock() if args.sim_time else WallClock()
    executive = build(site, tree, clock, settings, sim_time=args.sim_time)
    # first: what the keeper takes up from before a restart is recorded by the recorder
    keeper = Keeper(settings.checkpoint, fresh=args.fresh) if settings.checkpoint else None
    if keeper is not None:
        attach_all(executive, [keeper])
    attach_all(executive, [ExitRules(once=args.once)])  # --once, and the tree giving up
    attach_all(executive, [QuietCollector()])  # the collector at quiet turns, not in a tick
    if args.watch:  # a reloaded tree: the old one collected, the new one frozen
        attach_all(executive, [HeapKeeper()])
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, executive.stop, f"stopped by {sig.name}", 0)
    summary = None
    if args.once:  # the summary printed after one tour
        from frog_bt.live.summary import TourSummary

        summary = TourSummary(site)
        attach_all(executive, [summary])
    status: StatusLine | None = None
    if not args.quiet:  # on a terminal a countdown; in a journal, states only
        line = StatusLine(source=lambda: executive.status_text(countdown=line.tty))
        status = line
    refresher = None
    if status is not None:
        attach_all(executive, [status])
        # The tree does not tick while rosbridge is unreachable (or before /clock):
        # the line must still say what the executive is waiting for.
        refresher = asyncio.create_task(_refresh(status))
    observers = attach_observers(executive, record=settings.record, rerun=settings.rerun)
    try:
        people = await start_people(executive, console, observers)
    except UsageError:
        close_all(observers)
        raise
    watcher = None
    if args.watch:
        from frog_bt.runtime.watch import Watch

        watch = Watch(args.tree, args.config, tree, executive.offer)
        watcher = asyncio.create_task(watch.run())
    try:
        outcome = await executive.run()
    except (asyncio.CancelledError, KeyboardInterrupt):
        raise
    except BaseException as exc:  # a crash: the next start must not loop into it
        if keeper is not None:
            keeper.crashed(exc)
        raise
    finally:
        if watcher is not None:
            watcher.cancel()
        if refresher is not None:
            refresher.cancel()
        await people.close(deliver=executive.outcome.code != 0)
        close_all(observers)
        if status is not None:
            status.close()
    if summary is not None and executive.core.ticks:
        print("\n".join("  " + line for line in summary.lines(executive.link.stats)))
    if outcome.code:
        print(f"frog-bt: {outcome.reason}", file=sys.stderr)
    return outcome.code


def build(
    site: Site, tree: Any, clock: Clock, settings: Settings, *, sim_time: bool = False
) -> Executive:
    """The executive, handed its links: a rosbridge client of ``settings.url`` and the UDP
    link listening on ``settings.listen`` for the front end at ``settings.frontend``."""
    from frog_bt.frontend.link import FrontendLink
    from frog_bt.model.frontend import EVENTS
    from frog_bt.rosbridge.client import RosbridgeClient
    from frog_bt.runtime.executive import Executive

    client = RosbridgeClient(settings.url, secret=settings.secret)
    link = FrontendLink(settings.listen, settings.frontend, clock, inbound=EVENTS)
    return Executive(site, tree, clock, client, link, sim_time=sim_time)


async def _refresh(status: Any, interval: float = 0.5) -> None:
    """Redraw the status line every ``interval`` wall seconds (display only, not tour time)."""
    while True:
        await asyncio.sleep(interval)
        status.update()
