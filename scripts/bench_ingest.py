"""Ingestion: inbound rosbridge messages per second absorbed while the tree ticks, and memory.

A fake rosbridge server (here) floods one topic at a time as fast as the client
reads: robot poses, face data (three faces a message) and person detections (three
persons, each message calling for a tick). The client is, in turn,

* the executive (``bench_executive.py``, wall clock, its own process), mid-tour:
  undocked and driving to POI0, ticking at 10 Hz and on every detection;
* roslibpy (``bench_roslibpy.py``, its own process), subscribed to the same topics.

Each counts what it takes off the socket; the rate is the count over a window
after a warm-up, asked of the client itself. The executive's memory is read before
and after each flood, and its peak at the end. The server's own CPU share is
reported too: near 100% it, not the client, set the pace.

    .venv/bin/python scripts/bench_ingest.py --seconds 5
"""

from __future__ import annotations

import argparse
import asyncio
import importlib.util
import json
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import (
    LOOPBACK,
    SCRIPTS,
    SITE_FILE,
    Child,
    FakeFrontend,
    FakeRosbridge,
    emit,
    free_port,
)

WARMUP = 0.5  # seconds of flood before the window opens


def frames(kind: str, count: int = 256) -> list[str]:
    """``count`` distinct publish frames of one kind (stamps differ), as rosbridge sends them."""
    from frog_bt.sim import msgs

    out = []
    t0 = 1780302600.0
    for i in range(count):
        t = t0 + i * 0.01
        if kind == "pose":
            topic, msg = "/FROG_pose", msgs.pose_stamped(100.0 + i * 0.01, 30.0, 0.0, 1.0, t)
        elif kind == "faces":
            topic, msg = (
                "/ICL_FaceDataStream",
                msgs.face_data(
                    t,
                    [
                        {"id": j, "engagement": 0.5 - 0.1 * j, "distance": 1.2 + j, "facing": True}
                        for j in range(3)
                    ],
                ),
            )
        else:
            topic, msg = (
                "/UvA_PersonDetectionAndPose",
                msgs.person_detections(
                    t,
                    [
                        {"id": j, "position": (103.0 + j, 36.0), "orientation": 170.0 + 5 * j}
                        for j in range(3)
                    ],
                ),
            )
        out.append(json.dumps({"op": "publish", "topic": topic, "msg": msg}, separators=(",", ":")))
    return out


class Flood:
    """Sends ``texts`` round and round to the server's client until stopped, counting."""

    def __init__(self, server: FakeRosbridge, texts: list[str]) -> None:
        self.sent = 0
        self.stopped = False
        self.task = asyncio.ensure_future(self._run(server.ws, texts))

    async def _run(self, ws: Any, texts: list[str]) -> None:
        while not self.stopped and ws is not None:
            for text in texts:
                await ws.send(text)
                self.sent += 1
            await asyncio.sleep(0)  # let the window's timer run

    async def stop(self) -> None:
        self.stopped = True
        await self.task


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far (Linux), or NaN."""
    import os

    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        return float("nan")


async def one_flood(
    server: FakeRosbridge, child: Child, kind: str, seconds: float
) -> dict[str, Any]:
    sender = Flood(server, frames(kind))
    await asyncio.sleep(WARMUP)
    cpu0, client_cpu0, sent0 = time.process_time(), cpu_seconds(child.proc.pid), sender.sent
    before = await child.ask("stats")
    await asyncio.sleep(seconds)
    after = await child.ask("stats")
    cpu, sent = time.process_time() - cpu0, sender.sent - sent0
    client_cpu = cpu_seconds(child.proc.pid) - client_cpu0
    await sender.stop()
    await asyncio.sleep(0.3)  # let the client drain what is in flight
    span = after["t"] - before["t"]
    out = {
        "msg_per_s": (after["received"] - before["received"]) / span,
        "server_sent_per_s": sent / span,
        "server_cpu_share": cpu / span,
        "client_cpu_share": client_cpu / span,
    }
    if "ticks" in after:
        out["ticks_per_s"] = (after["ticks"] - before["ticks"]) / span
        out["rss_before_kb"], out["rss_after_kb"] = before["rss_kb"], after["rss_kb"]
    return out


async def measure(seconds: float, kinds: list[str]) -> dict[str, Any]:
    from frog_bt.model.frontend import FrontendIdle
    from frog_bt.model.wire import INPUTS

    result: dict[str, Any] = {"seconds": seconds}

    answers: set[asyncio.Future[int]] = set()

    def on_publish(topic: str, msg: Any, _t: int) -> None:
        if topic == "/docking/dock" and msg.get("data") == "undock":
            answer = asyncio.ensure_future(server.publish("/docking/state", {"data": "undocked"}))
            answers.add(answer)
            answer.add_done_callback(answers.discard)

    server = FakeRosbridge(on_publish, expect_subscriptions=len(INPUTS))
    await server.start()
    listen = free_port()
    front = FakeFrontend((LOOPBACK, listen))
    front_port = await front.open()
    try:
        # the executive, driving to POI0
        child = await Child.start(
            sys.executable,
            SCRIPTS / "bench_executive.py",
            "--config",
            SITE_FILE,
            "--rosbridge",
            server.url,
            "--frontend",
            f"{LOOPBACK}:{front_port}",
            "--listen",
            f"{LOOPBACK}:{listen}",
        )
        await asyncio.wait_for(server.ready.wait(), 30)
        await server.publish("/docking/state", {"data": "docked"})
        front.send(FrontendIdle())
        await asyncio.sleep(0.5)
        executive: dict[str, Any] = {"idle": await child.ask("stats")}
        for kind in kinds:
            executive[kind] = await one_flood(server, child, kind, seconds)
        executive["end"] = await child.ask("stats")
        await child.finish()
        result["executive"] = executive
        # roslibpy on the same server and the same floods
        if importlib.util.find_spec("roslibpy") is None:
            result["roslibpy"] = {"skipped": "roslibpy is not installed: pip install -e '.[bench]'"}
            return result
        server.ready.clear()
        child = await Child.start(
            sys.executable, SCRIPTS / "bench_roslibpy.py", "--port", str(server.port)
        )
        await asyncio.wait_for(server.ready.wait(), 30)
        result["roslibpy"] = {kind: await one_flood(server, child, kind, seconds) for kind in kinds}
        await child.finish()
    finally:
        front.close()
        await server.stop()
    return result


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=5.0, help="window per flood")
    p.add_argument("--kinds", default="pose,faces,persons")
    p.add_argument("--out")
    args = p.parse_args()
    emit(asyncio.run(measure(args.seconds, args.kinds.split(","))), args.out)


if __name__ == "__main__":
    main()
