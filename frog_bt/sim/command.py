"""Run the built-in simulator: a rosbridge v2 server playing the FROG robot, and a
UDP front end playing the content screen, until interrupted (Ctrl-C / SIGTERM).

Point the executive at it and run it on simulated time:

    frog-bt sim --scenario default --speed 50
    frog-bt run --rosbridge ws://127.0.0.1:9090 --sim-time

Or put a rosbridge server between them (a real rosbridge_suite; or `frog-bt sim
--relay`, a server with no robot inside): the simulated robot is then a client of it.

    frog-bt sim --relay --rosbridge 127.0.0.1:9190          # or a real rosbridge_suite
    frog-bt sim --via ws://127.0.0.1:9190 --speed 10
    frog-bt run --rosbridge ws://127.0.0.1:9190 --sim-time

Or play a recorded tour (the seed's recorded-data simulator), open loop: its robot-side
inputs over rosbridge on the recording's own clock (--speed, default 1x), its front-end
events over UDP; the commands of the executive run against it are held against the
recorded ones, and the first difference is printed in replay's terms:

    frog-bt sim --play recordings/20260601-103012-tour0003.mcap --speed 10 [--loop]
    frog-bt run --rosbridge ws://127.0.0.1:9090 --sim-time --once

It starts when the executive subscribes (or after a minute without one), plays a
tour file of --record DIR after the idle file it continues, acks the executive's
front-end commands (the protocol, not a reaction), and keeps /clock going after the
recording's end until interrupted; --loop plays it again, later (the clock never goes
back). The counts are printed at the end and on exit. A file that is not a recording,
or has no robot-side input, is exit 2. More in docs/RECORDING.md.

Time: the simulator is the master clock. It publishes /clock, starting at the
scenario's start_time, and runs `speed` times faster than real time (--speed
overrides the scenario; 50 = 50x). When the machine cannot keep up, simulated
time just runs slower.

Scenarios: --scenario takes a built-in name (default, morning, afternoon,
bored, no_visitor, declines, wander_off, nav_failure, undock_failure, fault,
silent_frontend; where the robot asks a person for help: dock_fails, undock_fails,
home_fails, fault_persists; and where the robot's word is not to be taken as it comes:
late_arrival, long_fault, out_of_order) or the path of a YAML file. Every key is
optional; `extends: NAME|FILE` starts from another scenario. Times called `at`
are seconds of simulated time after the start.

    extends: default
    start_time: 2026-06-01T15:00:00+02:00   # local time picks POI1b / POI2b
    speed: 50                     # x real time
    dt: 0.1                       # simulated seconds per step
    seed: 0                       # face data randomness
    detection_range: 15           # metres: people farther away are not seen
    robot: {start: SHOP, docked: true}      # or pose: {x, y, yaw (degrees)}
    navigation:
      speed: 0.6                  # m/s, straight line to each /GotoWayPoint
      approach_time: 3            # s per /ApproachPeopleFar
      failures:                   # 3 failed / 4 aborted after `after` s of driving
        - {goal: 2, result: aborted, after: 5}      # the 2nd goal of the run
        - {poi: POI2, times: 1, result: failed}     # the first goal to POI2a/b
      late:                       # answers held back: they come after a newer goal
        - {poi: POI2, delay: 2, duplicate: false}   # no poi: every goal's answers
    docking: {undock_time: 5, dock_time: 10, undock_failures: 0, dock_failures: 0}
    battery: {start: 90, drain_per_hour: 5, charge_per_hour: 20}
    faults: [{at: 600, name: motors, level: 2, message: overheated, duration: 60}]
                                  # or on_arrival: POI2 (from the first arrival there);
                                  # pad_to: 9216 repeats the message to that length
    visitors:
      - id: 7
        position: [103, 36]       # map frame
        facing: true              # or orientation: 180 (degrees, 180 = facing)
        appear_at: 0              # s; never: does not appear
        approach: [aborted, succeeded]   # results of successive approaches; or
                                  # one result for every approach (failed)
        answer: positive          # or negative (the visitor then leaves)
        faces: engaged            # bored, mixed, far, not_facing, or [0.5, -0.3]
        follow: true              # follows the robot once the tour starts
        wander_off: {heading_to: POI2}   # or {at: 900}
        after_tour: leave         # stay, or return (a new visitor comes)
    frontend:
      idle_at: 1                  # first frontend_idle
      idle_after_tour: 5          # frontend_idle again after a tour; null: never
      answer_delay: 2             # ask_tour -> user_positive / user_negative
      restarts: [1200]            # the front end restarts and says idle again
      ack: true                   # false: never acks commands
      silent: false               # true: a dead front end (sends nothing)
      silent_between: [[900, 960]]  # s: hangs then (no acks, no events), then wakes
      silent_from: null           # s: hangs from then on
      loss: 0.2                   # each datagram, either way, lost with this probability
      never_sends: [finish_introduction]  # events it never sends (a broken player)
    content: {default: 30, introduction: 20, POI1: {a: 40, b: 20}, POI3: 25}

What the robot does: drives straight to each goal and answers /FROG_response
1 then 2 (3/4 as scripted); undocks and docks with /docking/state; reports
people within range on /UvA_PersonDetectionAndPose and /PeopleUPO; streams
/ICL_FaceDataStream between /ICL_command start and stop; /diagnostic at 1 Hz.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import logging
import signal
import socket
import sys
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

from frog_bt.clock import SITE_TZ

if TYPE_CHECKING:
    from frog_bt.sim.scenario import Scenario
    from frog_bt.sim.site import PoiPose
    from frog_bt.sim.traffic import Record

log = logging.getLogger(__name__)


def _address(text: str) -> tuple[str, int]:
    """``HOST:PORT`` (or ``ws://HOST:PORT``) -> (host, port)."""
    rest = text.split("://", 1)[-1].rstrip("/")
    host, sep, port = rest.rpartition(":")
    if not sep or not host or not port.isdigit() or int(port) > 65535:
        raise argparse.ArgumentTypeError(f"expected HOST:PORT, got {text!r}")
    return host, int(port)


def _speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a speed factor > 0, got {text!r}")
    return value


def describe(record: Record) -> str:
    """One ``--log`` line: local time of day, side, direction, channel, compact JSON."""
    when = datetime.fromtimestamp(record.t, SITE_TZ).strftime("%H:%M:%S.%f")[:-5]
    arrow = "->" if record.direction == "out" else "<-"
    payload = json.dumps(record.payload, separators=(",", ":"), default=str)
    return f"{when} {record.side:<8} {arrow} {record.channel} {payload}"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--scenario",
        default="default",
        metavar="NAME|FILE",
        help="built-in scenario name or YAML file (default: default)",
    )
    parser.add_argument(
        "--speed",
        type=_speed,
        metavar="X",
        help="speed factor, simulated seconds per real second (default: the scenario's)",
    )
    parser.add_argument(
        "--rosbridge",
        type=_address,
        default=("127.0.0.1", 9090),
        metavar="HOST:PORT",
        help="where the rosbridge server listens (default 127.0.0.1:9090)",
    )
    parser.add_argument(
        "--frontend",
        type=_address,
        default=("127.0.0.1", 5005),
        metavar="HOST:PORT",
        help="where the simulated front end listens (default 127.0.0.1:5005)",
    )
    parser.add_argument(
        "--executive",
        type=_address,
        default=("127.0.0.1", 5006),
        metavar="HOST:PORT",
        help="where the executive listens for the front end (default 127.0.0.1:5006)",
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="FILE",
        help="site configuration with the POI table (default: the packaged "
        "config/site.yaml; 'frog-bt init DIR' copies it to edit)",
    )
    parser.add_argument(
        "--secret",
        default=None,
        help="rosauth secret: clients of the simulator's server must "
        "authenticate with it; with --via, the simulator does",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--via",
        default=None,
        metavar="ws://HOST:PORT",
        help="serve no rosbridge: be the robot as a client of this rosbridge "
        "server (a real rosbridge_suite, say); the executive connects "
        "to the same server",
    )
    where.add_argument(
        "--play",
        type=Path,
        metavar="FILE.mcap",
        help="serve a recorded tour's robot-side inputs on the recording's own "
        "clock, and its front-end events over UDP, open loop; say where a "
        "new executive's commands differ from the recorded ones",
    )
    where.add_argument(
        "--relay",
        action="store_true",
        help="only a rosbridge server with no robot inside, on --rosbridge: "
        "publishes from one client go to the others' subscriptions "
        "(a stand-in for rosbridge_suite, for --via)",
    )
    parser.add_argument(
        "--loop",
        action="store_true",
        help="with --play: play the recording again from its start, for ever "
        "(the clock goes on forward)",
    )
    parser.add_argument(
        "--log",
        action="store_true",
        help="print every message as it is sent or received, one line each",
    )


def run(args: argparse.Namespace) -> int:
    from frog_bt.config import DEFAULT_CONFIG
    from frog_bt.errors import ConfigError
    from frog_bt.sim.scenario import load_scenario
    from frog_bt.sim.site import load_pois

    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    try:
        scenario = load_scenario(args.scenario)
        pois = load_pois(args.config or DEFAULT_CONFIG)
    except ConfigError as exc:
        print(f"frog-bt sim: {exc}", file=sys.stderr)
        return 2
    if args.loop and args.play is None:
        print("frog-bt sim: --loop goes with --play FILE.mcap", file=sys.stderr)
        return 2
    if args.speed is not None:
        scenario = scenario.model_copy(update={"speed": args.speed})
    if args.via is not None:
        from websockets.exceptions import InvalidURI
        from websockets.uri import parse_uri

        try:
            parse_uri(args.via)
        except InvalidURI:
            print(f"frog-bt sim: --via {args.via!r}: expected ws://HOST:PORT", file=sys.stderr)
            return 2
    try:
        if args.play is not None:
            return asyncio.run(_play(args))
        if args.relay:
            return asyncio.run(_relay(args))
        return asyncio.run(_serve(args, scenario, pois))
    except ConfigError as exc:
        print(f"frog-bt sim: {exc}", file=sys.stderr)
        return 2


async def _serve(args: argparse.Namespace, scenario: Scenario, pois: dict[str, PoiPose]) -> int:
    from frog_bt.sim.simulator import Simulator

    sim = Simulator(
        scenario,
        host=args.rosbridge[0],
        rosbridge_port=args.rosbridge[1],
        frontend_host=args.frontend[0],
        frontend_port=args.frontend[1],
        executive=args.executive,
        pois=pois,
        secret=args.secret,
        via=args.via,
    )
    if args.log:
        sim.log.add_listener(lambda record: print(describe(record), flush=True))
    try:
        await sim.start()
    except OSError as exc:
        return _cannot_listen(args, exc)
    bridge = (
        f"robot via rosbridge {args.via}"
        if args.via is not None
        else f"rosbridge ws://{args.rosbridge[0]}:{sim.rosbridge_port}"
    )
    print(
        f"frog-bt sim: {bridge}, "
        f"front end udp {args.frontend[0]}:{sim.frontend_port} -> executive "
        f"{args.executive[0]}:{args.executive[1]}, scenario {sim.scenario.name or '?'}, "
        f"{sim.speed:g}x from {sim.scenario.start_time.isoformat()}",
        flush=True,
    )
    stopping = _stop_on_signals()
    clock = asyncio.create_task(sim.wait_clock_stopped())
    await asyncio.wait([stopping, clock], return_when=asyncio.FIRST_COMPLETED)
    stopping.cancel()
    clock.cancel()
    try:
        await sim.stop()
    except Exception as exc:  # the time loop died of a bug; it was logged
        print(f"frog-bt sim: simulation failed: {exc!r}", file=sys.stderr)
        return 1
    print(
        f"frog-bt sim: stopped at {sim.clock.local_time().isoformat(timespec='seconds')}",
        flush=True,
    )
    return 0


def _stop_on_signals() -> asyncio.Task[bool]:
    """A task that ends on SIGINT or SIGTERM."""
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError):
            loop.add_signal_handler(sig, stop.set)
    return asyncio.create_task(stop.wait())


def _cannot_listen(args: argparse.Namespace, exc: OSError) -> int:
    """One line naming the address that could not be bound (found by trying each of
    ``--rosbridge`` (TCP) and ``--frontend`` (UDP) again), exit 2 as any bad option."""
    reason = exc.strerror or str(exc)
    for flag, (host, port), kind in (
        ("--rosbridge", args.rosbridge, socket.SOCK_STREAM),
        ("--frontend", args.frontend, socket.SOCK_DGRAM),
    ):
        if not port:
            continue
        with socket.socket(socket.AF_INET, kind) as probe:
            if kind == socket.SOCK_STREAM:
                probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind((host, port))
            except OSError as busy:
                reason = busy.strerror or str(busy)
                print(
                    f"frog-bt sim: {flag} {host}:{port}: cannot listen there: {reason}",
                    file=sys.stderr,
                )
                return 2
    print(f"frog-bt sim: cannot listen: {reason}", file=sys.stderr)
    return 2


async def _relay(args: argparse.Namespace) -> int:
    from frog_bt.sim.rosbridge_server import RosbridgeServer

    server = RosbridgeServer.relay(args.rosbridge[0], args.rosbridge[1], args.secret)
    try:
        await server.start()
    except OSError as exc:
        return _cannot_listen(args, exc)
    print(
        f"frog-bt sim: relaying rosbridge ws://{args.rosbridge[0]}:{server.port} "
        f"(no robot inside{'; clients authenticate' if args.secret else ''})",
        flush=True,
    )
    await _stop_on_signals()
    await server.stop()
    print("frog-bt sim: stopped", flush=True)
    return 0


async def _play(args: argparse.Namespace) -> int:
    from frog_bt.config import load_site
    from frog_bt.sim.play import Player, PlayError, load

    site = load_site(args.config)
    try:
        played = load(args.play, site)
    except PlayError as exc:
        print(f"frog-bt sim: --play: {exc}", file=sys.stderr)
        return 2
    speed = args.speed or 1.0

    def differ(text: str) -> None:
        print(f"frog-bt sim: the executive parted from the recording {text}", flush=True)

    player = Player(
        played,
        site,
        host=args.rosbridge[0],
        rosbridge_port=args.rosbridge[1],
        frontend_host=args.frontend[0],
        frontend_port=args.frontend[1],
        executive=args.executive,
        speed=speed,
        loop=args.loop,
        secret=args.secret,
        on_difference=differ,
    )
    try:
        await player.start()
    except OSError as exc:
        return _cannot_listen(args, exc)
    print(
        f"frog-bt sim: playing {', '.join(played.files)} ({len(played.inputs)} inputs, "
        f"{len(played.events)} front-end events, {played.end - played.start:.0f} s) at "
        f"{speed:g}x{' in a loop' if args.loop else ''}: rosbridge "
        f"ws://{args.rosbridge[0]}:{player.rosbridge.port}, front end udp "
        f"{args.frontend[0]}:{player.udp.port} -> executive "
        f"{args.executive[0]}:{args.executive[1]}; it starts when an executive subscribes "
        "(at most a minute from now)",
        flush=True,
    )
    stopping = _stop_on_signals()
    over = asyncio.create_task(player.over.wait())
    clock = asyncio.create_task(player.wait())
    await asyncio.wait([stopping, over, clock], return_when=asyncio.FIRST_COMPLETED)
    if over.done() and not stopping.done():
        print(
            f"frog-bt sim: the recording is over; {player.summary()}; the clock goes on "
            "until interrupted",
            flush=True,
        )
        await asyncio.wait([stopping, clock], return_when=asyncio.FIRST_COMPLETED)
    for task in (stopping, over, clock):
        task.cancel()
    try:
        await player.stop()
    except Exception as exc:  # the time loop died of a bug; it was logged
        print(f"frog-bt sim: play failed: {exc!r}", file=sys.stderr)
        return 1
    print(f"frog-bt sim: stopped; {player.summary()}", flush=True)
    return 0
