"""The --rerun spec: what is accepted, and errors that say what was expected."""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

import pytest

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.live.telemetry import Telemetry
from frog_bt.live.telemetry.spec import DEFAULT_URL, Sink, parse_spec


@pytest.mark.parametrize(
    ("spec", "sink"),
    [
        ("spawn", Sink("spawn")),
        ("save:tour.rrd", Sink("save", "tour.rrd")),
        ("save:/tmp/a b/tour.rrd", Sink("save", "/tmp/a b/tour.rrd")),
        ("connect", Sink("connect", DEFAULT_URL)),
        ("connect:", Sink("connect", DEFAULT_URL)),
        (
            "connect:rerun+http://127.0.0.1:9877/proxy",
            Sink("connect", "rerun+http://127.0.0.1:9877/proxy"),
        ),
        ("serve", Sink("serve")),
        ("serve:9900", Sink("serve", port=9900)),
    ],
)
def test_accepted_specs(spec: str, sink: Sink):
    assert parse_spec(spec) == sink


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("", "expected spawn, save:FILE.rrd, connect[:URL] or serve[:PORT]"),
        ("view", "expected spawn, save:FILE.rrd"),
        ("spawn:9876", "expected spawn"),
        ("save", "save needs a file"),
        ("save:", "save needs a file"),
        ("save:tour.mcap", "should end in .rrd"),
        ("connect:http://127.0.0.1:9876", "expected a URL like rerun+http://127.0.0.1:9876/proxy"),
        ("connect:rerun+http://127.0.0.1:9876", "expected a URL like"),
        ("serve:web", "expected serve or serve:PORT"),
        ("serve:0", "expected serve or serve:PORT"),
        ("serve:70000", "expected serve or serve:PORT"),
    ],
)
def test_bad_specs_say_what_was_expected(spec: str, message: str):
    with pytest.raises(ValueError, match="rerun telemetry spec") as info:
        parse_spec(spec)
    assert message in str(info.value)
    assert repr(spec) in str(info.value)


def test_open_rejects_a_bad_spec_before_starting_anything():
    site = load_site()
    with pytest.raises(ValueError, match="save needs a file"):
        Telemetry.open("save:", site, load_tree(site=site))


def test_importing_telemetry_does_not_import_rerun():
    code = (
        "import sys, frog_bt.live.telemetry, frog_bt.live.telemetry.rows, "
        "frog_bt.live.telemetry.layout, frog_bt.live.telemetry.site_map, "
        "frog_bt.live.telemetry.spec; "
        "sys.exit('rerun imported' if 'rerun' in sys.modules else 0)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stdout + result.stderr


def listening(port: int) -> set[str]:
    """The local addresses (hex, as the kernel lists them) listening on TCP ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            local, state = line.split()[1], line.split()[3]
            address, hex_port = local.rsplit(":", 1)
            if state == "0A" and int(hex_port, 16) == port:  # 0A: LISTEN
                found.add(address)
    return found


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="needs Linux's /proc/net/tcp")
def test_serve_listens_on_loopback_only():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    site = load_site()
    telemetry = Telemetry.open(f"serve:{port}", site, load_tree(site=site))
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass
        # The kernel's own table: bound to 127.0.0.1 (0100007F), not to every address
        # (00000000 or ::) — checked without sending anything anywhere else.
        assert listening(port) == {"0100007F"}
    finally:
        telemetry.close()
        telemetry.close()  # idempotent
