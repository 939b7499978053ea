"""systemd's notify protocol with a fake notify socket: READY arrives, the watchdog is
pinged at its interval from the tick loop, and a loop that stops (here: the process
stopped with SIGSTOP, as a wedged loop looks to systemd) stops the pings."""

from __future__ import annotations

import asyncio
import os
import signal
import socket
import sys
from pathlib import Path

from tour import fast, free_udp_port

from frog_bt.runtime.notify import Notifier
from frog_bt.sim import Simulator


def fake_systemd(path: Path) -> socket.socket:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(str(path))
    sock.setblocking(False)
    return sock


def drain(sock: socket.socket) -> list[str]:
    out = []
    while True:
        try:
            out += sock.recv(4096).decode().splitlines()
        except BlockingIOError:
            return out


def test_pings_come_at_half_the_watchdog_interval_by_the_clock(tmp_path: Path) -> None:
    sock = fake_systemd(tmp_path / "notify")
    now = [100.0]
    notifier = Notifier(str(tmp_path / "notify"), watchdog_usec=2_000_000, clock=lambda: now[0])
    notifier.ready("starting")
    for _ in range(40):  # the loop turns every 0.1 s for 4 s
        notifier.alive()
        notifier.status(lambda: f"at {now[0] // 2:.0f}")
        now[0] += 0.1
    got = drain(sock)
    assert got[:2] == ["READY=1", "STATUS=starting"]
    assert got.count("WATCHDOG=1") == 4  # every 1 s (half of WatchdogSec=2)
    statuses = [g for g in got if g.startswith("STATUS=at")]
    assert 2 <= len(statuses) <= 4  # at most once a second, and only when it changed
    sock.close()


def test_without_notify_socket_nothing_is_sent() -> None:
    notifier = Notifier.from_env({})
    assert not notifier.enabled
    notifier.ready()
    notifier.alive()  # no socket, no error


def test_the_executive_is_ready_pings_and_a_stopped_loop_stops_the_pings(tmp_path: Path) -> None:
    sock = fake_systemd(tmp_path / "notify")

    async def main() -> tuple[list[str], list[str], list[str]]:
        listen = free_udp_port()
        sim = Simulator(
            fast({"speed": 5.0}), rosbridge_port=0, frontend_port=0, executive=("127.0.0.1", listen)
        )
        await sim.start()
        env = {
            **os.environ,
            "NOTIFY_SOCKET": str(tmp_path / "notify"),
            "WATCHDOG_USEC": "200000",
        }  # a ping every 0.1 s
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "frog_bt",
            "run",
            "--sim-time",
            "--quiet",
            "--checkpoint",
            "none",
            "--rosbridge",
            f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend",
            f"127.0.0.1:{sim.frontend_port}",
            "--listen",
            f"127.0.0.1:{listen}",
            env=env,
            stdout=asyncio.subprocess.DEVNULL,
            stderr=asyncio.subprocess.DEVNULL,
        )
        loop = asyncio.get_running_loop()
        heard: list[str] = []

        async def listen_like_systemd() -> None:  # systemd reads its socket all along
            while True:
                heard.extend(drain(sock))
                await asyncio.sleep(0.02)

        listener = asyncio.create_task(listen_like_systemd())

        async def until_pings(n: int) -> list[str]:
            start = len(heard)
            deadline = loop.time() + 60.0  # a bound for a loaded machine, not a pace
            while heard[start:].count("WATCHDOG=1") < n:
                assert loop.time() < deadline, heard
                await asyncio.sleep(0.05)
            return heard[start:]

        try:
            await sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 60)
            running = heard[:] + await until_pings(3)
            proc.send_signal(signal.SIGSTOP)  # the loop can turn no more
            deadline = loop.time() + 10.0
            while not _stopped(proc.pid):  # the kernel has stopped it: nothing more is sent
                assert loop.time() < deadline
                await asyncio.sleep(0.01)
            heard.extend(drain(sock))  # every ping sent before it stopped, now
            mark = len(heard)
            await asyncio.sleep(1.0)  # the window watched: ten ping intervals
            heard.extend(drain(sock))
            stopped = heard[mark:]
            proc.send_signal(signal.SIGCONT)
            resumed = await until_pings(2)
            return running, stopped, resumed
        finally:
            listener.cancel()
            proc.send_signal(signal.SIGCONT)
            proc.terminate()
            await asyncio.wait_for(proc.wait(), 60)
            await sim.stop()

    running, stopped, resumed = asyncio.run(main())
    sock.close()
    assert running[0] == "READY=1"
    assert any(line.startswith("STATUS=") for line in running)
    assert "WATCHDOG=1" not in stopped  # systemd would restart it now
    assert resumed.count("WATCHDOG=1") >= 2


def _stopped(pid: int) -> bool:
    """Is the process stopped (state T in /proc/PID/stat)?"""
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()[0] in ("T", "t")


def test_init_service_writes_a_notify_unit_with_a_watchdog_for_that_folder(tmp_path: Path) -> None:
    import getpass

    from frog_bt.cli import main

    site = tmp_path / "alcazar"
    me = getpass.getuser()  # a user that exists: as root, init would create another one
    assert main(["init", str(site), "--service", "--user", me]) == 0
    unit = (site / "frog-bt.service").read_text()
    for line in (
        "Type=notify",
        "Restart=always",
        "WatchdogSec=10",
        f"User={me}",
        f"--tree {site.resolve()}/trees/tour.yaml",
        f"--config {site.resolve()}/config/site.yaml",
        f"--checkpoint {site.resolve()}/state/checkpoint.json",
    ):
        assert line in unit, line
    assert (site / "state").is_dir() and (site / "recordings").is_dir()
    assert main(["init", str(site), "--service"]) == 2  # exists: not overwritten
