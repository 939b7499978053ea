"""Reaction latency: an input frame on the socket to the command it causes leaving the other.

``frog-bt run`` (wall clock, in its own process) talks to a fake robot (a rosbridge
server) and a fake front end (a UDP peer) run here, which script a loop that
yields two trials per turn:

* ``/FROG_response 2 -> start_poi``: the robot arrives at the first stop with the
  visitor next to it; the time from writing the response frame to reading the
  ``start_poi`` datagram;
* ``user_positive -> /GotoWayPoint``: the visitor says yes; the time from writing
  the event datagram to reading the goal frame for the first stop.

Then the content is done, the robot drives to the second stop and arrives alone
(``follow.grace: 0``): the visitor is lost, the tree goes back to POI0 and
recruits again, and the loop turns. A trial starts just before the fake robot or front
end writes the input and ends when the kernel received the command on the other socket
(its receive timestamp, ``bench_support.StampingSocket``): the executive's reaction,
not the fake robot's own wake-up to read it. That longer figure, to the robot's read, is
kept beside it (``read by the robot``). Pose and person detections flow at 10 Hz
throughout.

    .venv/bin/python scripts/bench_reaction.py --trials 1000
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import (
    FROG_BT,
    LOOPBACK,
    FakeFrontend,
    FakeRosbridge,
    emit,
    free_port,
    summary_us,
    synthetic_site,
)

ARRIVAL = "response 2 -> start_poi"
ANSWER = "user_positive -> /GotoWayPoint"
WARMUP = 10  # trials of each kind left out at the start


class Director:
    """The fake robot and front end: answers every command the way the loop needs."""

    def __init__(self, site: Any, trials: int) -> None:
        from frog_bt.model import frontend as fm

        self.fm = fm
        self.site = site
        self.trials = trials
        self.stops = [s.poi for s in site.tour.stops]
        self.pois = {name: (p.x, p.y) for name, p in site.pois.items()}
        self.robot = self.pois[site.tour.dock]
        self.samples: dict[str, list[int]] = {ARRIVAL: [], ANSWER: []}
        self.read: dict[str, list[int]] = {ARRIVAL: [], ANSWER: []}  # to the robot's read
        self.pending: tuple[str, int] | None = None
        self.lost = False  # arrived at a stop without the visitor
        self.done = asyncio.Event()
        self.errors: list[str] = []
        self.server = FakeRosbridge(self.on_ros)
        self.frontend: FakeFrontend | None = None
        self._tasks: set[asyncio.Task[Any]] = set()

    def spawn(self, coro: Any) -> None:
        task = asyncio.ensure_future(coro)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    def finish_trial(self, kind: str, t: int, read: int) -> None:
        if self.pending is not None and self.pending[0] == kind:
            self.samples[kind].append(t - self.pending[1])
            self.read[kind].append(read - self.pending[1])
            self.pending = None
            if all(len(v) >= self.trials + WARMUP for v in self.samples.values()):
                self.done.set()
        else:
            self.errors.append(f"unexpected {kind} (pending {self.pending})")

    # ------------------------------------------------------------ robot side

    def on_ros(self, topic: str, msg: Any, t: int) -> None:
        if topic == "/GotoWayPoint":
            p = msg["pose"]["position"]
            target = min(self.pois, key=lambda n: math.dist(self.pois[n], (p["x"], p["y"])))
            self.lost = False
            if target == self.stops[0]:
                self.finish_trial(ANSWER, t, self.server.read_ns)
            self.spawn(self.arrive(target))
        elif topic == "/ApproachPeopleFar":
            self.spawn(self.server.publish("/FROG_response", {"data": 2}))
        elif topic == "/docking/dock":
            state = "undocked" if msg["data"] == "undock" else "docked"
            self.spawn(self.server.publish("/docking/state", {"data": state}))

    async def arrive(self, target: str) -> None:
        self.robot = self.pois[target]
        now = time.time()
        await self.server.publish("/FROG_pose", self.pose(now))
        if target in self.stops:
            with_visitor = target == self.stops[0]
            people = [{"id": 7, "position": self.near()}] if with_visitor else []
            await self.server.publish("/PeopleUPO", {"header": self.header(now), "people": people})
            self.lost = not with_visitor
            t0 = await self.server.publish("/FROG_response", {"data": 2})
            if with_visitor:
                self.pending = (ARRIVAL, t0)
        else:
            await self.server.publish("/FROG_response", {"data": 2})

    def near(self) -> dict[str, float]:
        return {"x": self.robot[0] + 1.0, "y": self.robot[1], "z": 0.0}

    @staticmethod
    def header(t: float) -> dict[str, Any]:
        secs = math.floor(t)
        return {
            "seq": 0,
            "stamp": {"secs": secs, "nsecs": int((t - secs) * 1e9)},
            "frame_id": "map",
        }

    def pose(self, t: float) -> dict[str, Any]:
        x, y = self.robot
        return {
            "header": self.header(t),
            "pose": {
                "position": {"x": x, "y": y, "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
            },
        }

    def persons(self, t: float) -> dict[str, Any]:
        return {
            "header": self.header(t),
            "persons": [{"id": 7, "position": self.near(), "orientation": 180.0}],
        }

    async def sensors(self) -> None:
        """Pose and person detections at 10 Hz, as the robot publishes them."""
        while True:
            now = time.time()
            await self.server.publish("/FROG_pose", self.pose(now))
            await self.server.publish("/UvA_PersonDetectionAndPose", self.persons(now))
            await asyncio.sleep(0.1)

    # ------------------------------------------------------------ front-end side

    def on_command(self, message: Any, t: int) -> None:
        fm, front = self.fm, self.frontend
        assert front is not None
        if isinstance(message, fm.StartPoi):
            self.finish_trial(ARRIVAL, t, front.read_ns)
            front.send(fm.ContentDone(message.poi, message.part))
        elif isinstance(message, fm.StartIntroduction):
            front.send(fm.FinishIntroduction())
        elif isinstance(message, fm.AskTour):
            self.pending = (ANSWER, front.send(fm.UserPositive()))
        elif isinstance(message, fm.Tour) and message.state != "started":
            front.send(fm.FrontendIdle())
        elif isinstance(message, fm.FollowMe) and not message.on and self.lost:
            self.spawn(self.nudge())

    async def nudge(self) -> None:
        """Detections every millisecond until the tree drives back to POI0.

        Finding the visitor gone and starting over take two more ticks after the
        arrival; detections bring them at once instead of the 10 Hz periodic tick,
        so that the loop turns quickly (no trial is timed meanwhile).
        """
        while self.lost:
            await self.server.publish("/UvA_PersonDetectionAndPose", self.persons(time.time()))
            await asyncio.sleep(0.001)


async def measure(
    trials: int, telemetry: bool, workdir: Path, stops: int = 7, probe: bool = False
) -> dict[str, Any]:
    from frog_bt.config import load_site
    from frog_bt.model.wire import INPUTS

    plain = {"content": True, "face_stream": False, "projector": False, "check_follower": True}
    site_path = synthetic_site(
        stops,
        workdir,
        flags=plain,
        over={"follow": {"grace": 0.0}, "recruit": {"approach_interval": 0.0}},
    )
    site = load_site(site_path)
    director = Director(site, trials)
    director.server.expect = len(INPUTS)
    await director.server.start()
    listen = free_port()
    director.frontend = FakeFrontend((LOOPBACK, listen), director.on_command)
    frontend_port = await director.frontend.open()
    argv = [
        str(FROG_BT),
        "run",
        "--config",
        str(site_path),
        "--rosbridge",
        director.server.url,
        "--frontend",
        f"{LOOPBACK}:{frontend_port}",
        "--listen",
        f"{LOOPBACK}:{listen}",
        "--checkpoint",
        "none",
        "--fresh",
        "--quiet",
    ]
    if telemetry:
        argv += [
            "--record",
            str(workdir / "reaction.mcap"),
            "--rerun",
            f"save:{workdir / 'reaction.rrd'}",
        ]
    env = None
    if probe:  # what held the executive's loop, in its CPU time (scripts/loop_probe)
        env = dict(os.environ, LOOP_PROBE_OUT=str(workdir / "loop"))
        env["PYTHONPATH"] = os.pathsep.join(
            p for p in (env.get("PYTHONPATH"), str(Path(__file__).parent / "loop_probe")) if p
        )
    proc = await asyncio.create_subprocess_exec(*argv, env=env)
    sensors = None
    wall0 = time.monotonic()
    try:
        await asyncio.wait_for(director.server.ready.wait(), 30)
        sensors = asyncio.ensure_future(director.sensors())
        await director.server.publish("/docking/state", {"data": "docked"})
        director.frontend.send(director.fm.FrontendIdle())
        await asyncio.wait_for(director.done.wait(), 60 + trials * 0.2)
    finally:
        if sensors is not None:
            sensors.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await sensors
        proc.terminate()
        await asyncio.wait_for(proc.wait(), 30)
        director.frontend.close()
        await director.server.stop()
    probed = [json.loads(f.read_text()) for f in workdir.glob("loop.*")]
    return {
        **({"loop": probed[0]} if probed else {}),
        "trials": trials,
        "stops": stops,
        "telemetry": telemetry,
        "wall_s": time.monotonic() - wall0,
        "errors": director.errors[:5],
        **{kind: summary_us(values[WARMUP:]) for kind, values in director.samples.items()},
        "read by the robot": {
            kind: summary_us(values[WARMUP:]) for kind, values in director.read.items()
        },
        # every trial (ns), for scripts/bench to pool rounds: {"measured"|"read": {kind: [...]}}
        "samples_ns": {
            "measured": {kind: values[WARMUP:] for kind, values in director.samples.items()},
            "read": {kind: values[WARMUP:] for kind, values in director.read.items()},
        },
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trials", type=int, default=1000)
    p.add_argument("--telemetry", choices=("on", "off"), default="off")
    p.add_argument(
        "--probe",
        action="store_true",
        help="also report what held the executive's event loop (its CPU time) and the "
        "collector's pauses (scripts/loop_probe)",
    )
    p.add_argument(
        "--stops", type=int, default=7, help="stops of the synthetic tour (the tree's size)"
    )
    p.add_argument("--out")
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
        result = asyncio.run(
            measure(
                args.trials, args.telemetry == "on", Path(tmp), stops=args.stops, probe=args.probe
            )
        )
    emit(result, args.out)


if __name__ == "__main__":
    main()
