"""Connection exhaustion, scaled down: under ``RLIMIT_NOFILE`` 256 (systemd's 1024 in the
issue), 300 connections held to the console while a tour runs. The console takes at most
half the descriptors and answers the rest with a plain 503, so the tour ends on time,
nothing logs a traceback, and the console answers once the connections close."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
from pathlib import Path

CHILD = Path(__file__).parent / "held_connections.py"


def test_held_connections_under_a_low_descriptor_limit_leave_the_tour_on_time() -> None:
    child = subprocess.Popen(
        [sys.executable, str(CHILD), "256"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert child.stdin is not None and child.stdout is not None
    held: list[socket.socket] = []
    try:
        url = child.stdout.readline().strip()
        host, port = url.removeprefix("http://").split(":")
        for _ in range(300):
            sock = socket.socket()
            sock.settimeout(10)
            sock.connect((host, int(port)))
            held.append(sock)
        child.stdin.write("held\n")
        child.stdin.flush()
        assert child.stdout.readline().strip() == "ended"
        answered = [sock.recv(12) for sock in held[-50:]]  # the last ones: over the cap
        for sock in held:
            sock.close()
        child.stdin.write("closed\n")
        child.stdin.flush()
        result = json.loads(child.stdout.readline())
    finally:
        for sock in held:
            sock.close()
        child.kill() if child.poll() is None else None
        child.wait(30)
    assert (result["code"], result["tours"]) == (0, 1), result
    assert result["cap"] == 128 and result["refused"] >= 300 - 128, result
    assert answered == [b"HTTP/1.1 503"] * 50
    assert result["lag"] < 0.5, result  # the tick (100 ms) kept its pace, within a bound
    assert result["tracebacks"] == 0 and result["state"] == 200, result
    # the console kept to its half, accept bursts included: the tour never ran short
    assert result["out_of_files"] == 0, result
