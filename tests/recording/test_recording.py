"""MCAP recordings (CONTRACT §6): channels, schemas, stamps; valid after SIGTERM or a crash."""

from __future__ import annotations

import asyncio
import json
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from hypothesis import given
from hypothesis import strategies as st
from mcap.reader import make_reader
from recorded_tour import RecordedTour, scenario
from rosmsgs import encode_clock

from frog_bt.clock import SimClock
from frog_bt.config import load_site
from frog_bt.live.recording import Recorder
from frog_bt.model.channels import (
    DATAGRAM_TYPE,
    FRONTEND_IN,
    FRONTEND_OUT,
    TICK,
    from_ns,
    schema_for,
    to_ns,
)
from frog_bt.model.events import Datagram, RobotInput
from frog_bt.model.links import Links, LinkStatus
from frog_bt.model.run import RunId
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.rehearsal import free_udp_port
from frog_bt.runtime import background
from frog_bt.runtime.observer import Observers, attach_all
from frog_bt.sim import Simulator

ROOT = Path(__file__).resolve().parents[2]
JSON_TYPES: dict[str, Any] = {
    "object": dict,
    "array": list,
    "string": str,
    "boolean": bool,
    "null": type(None),
    "number": (int, float),
    "integer": int,
}


def conforms(value: Any, schema: dict[str, Any]) -> bool:
    """The subset of JSON Schema the recorder writes: type, properties, items, enum,
    required, additionalProperties (a schema), anyOf, minimum/maximum; keys not
    described are errors."""
    if "anyOf" in schema and not any(conforms(value, s) for s in schema["anyOf"]):
        return False
    if "enum" in schema and value not in schema["enum"]:
        return False
    if "minimum" in schema and isinstance(value, int | float) and value < schema["minimum"]:
        return False
    if "maximum" in schema and isinstance(value, int | float) and value > schema["maximum"]:
        return False
    types = schema.get("type")
    if types is not None:
        types = [types] if isinstance(types, str) else types
        ok = [
            t
            for t in types
            if isinstance(value, JSON_TYPES[t])
            and not (t in ("number", "integer") and isinstance(value, bool))
        ]
        if not ok:
            return False
    if isinstance(value, dict):
        props = schema.get("properties", {})
        extra = schema.get("additionalProperties")
        return all(k in value for k in schema.get("required", ())) and all(
            conforms(v, props[k]) if k in props else isinstance(extra, dict) and conforms(v, extra)
            for k, v in value.items()
        )
    if isinstance(value, list) and "items" in schema:
        return all(conforms(v, schema["items"]) for v in value)
    return True


def read_all(path: Path) -> tuple[Any, list[tuple[Any, Any, Any]]]:
    """Summary and every message, in file order (make_reader fails on an invalid file)."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        messages = list(reader.iter_messages(log_time_order=False))
    return summary, messages


def test_a_recorded_tour_has_every_channel_typed_and_stamped(tour: RecordedTour) -> None:
    summary, messages = read_all(tour.path)
    assert summary is not None and summary.statistics.message_count == len(messages)
    types = {t.name: t.type for t in (*INPUTS.values(), *OUTPUTS.values(), CLOCK)}
    types |= {FRONTEND_IN: DATAGRAM_TYPE, FRONTEND_OUT: DATAGRAM_TYPE}
    counts: dict[str, int] = {}
    last = 0
    schemas: dict[str, dict[str, object]] = {}
    for schema, channel, message in messages:
        if schema.name not in schemas:
            schemas[schema.name] = schema_for(schema.name)
        expected = schemas[schema.name]
        counts[channel.topic] = counts.get(channel.topic, 0) + 1
        if channel.topic in types:
            assert schema.name == types[channel.topic], channel.topic
        assert channel.message_encoding == "json" and schema.encoding == "jsonschema"
        assert json.loads(schema.data) == expected
        assert message.publish_time == message.log_time >= last
        last = message.log_time
        assert tour.start <= from_ns(message.log_time) <= tour.end
        assert conforms(json.loads(message.data), expected), (channel.topic, message.data)
    assert set(types) <= set(counts), set(types) - set(counts)  # every channel had traffic
    assert counts[TICK] == tour.executive.core.ticks

    # The ROS commands recorded are the ones the robot got, in order.
    recorded = [
        (c.topic, json.loads(m.data))
        for _, c, m in messages
        if c.topic in {t.name for t in OUTPUTS.values()}
    ]
    assert recorded == [(r.channel, r.payload) for r in tour.received if r.side == "ros"]
    # Front-end commands too (resends share a seq; acks are the executive's answers).
    commands: dict[int, tuple[str, dict[str, Any]]] = {}
    for _, c, m in messages:
        if c.topic == FRONTEND_OUT:
            data = json.loads(m.data)
            if data["type"] != "ack":
                commands.setdefault(data.pop("seq"), (data.pop("type"), data))
    got = [
        (r.channel, r.payload) for r in tour.received if r.side == "frontend" and r.channel != "ack"
    ]
    assert len(got) > 10 and got == list(commands.values())[: len(got)]


def fake_executive() -> Any:
    site = load_site()
    links = Links(LinkStatus.CONNECTED, LinkStatus.ACKING, LinkStatus.SIM)
    return SimpleNamespace(
        site=site,
        sim_time=True,
        clock=SimClock(),
        observers=Observers(),
        core=SimpleNamespace(tree=None, standing=SimpleNamespace(run=RunId.new())),
        links=links,
    )


def wire_of(
    executive: Any,
) -> tuple[Callable[[str, bytes, float], None], Callable[[float, str, Any], None]]:
    """(datagram(direction, data, t), ros_in(t, topic, msg)): raw traffic as the live
    executive tells its observers."""

    def datagram(direction: str, data: bytes, t: float) -> None:
        executive.observers.emit(Datagram(t, "in" if direction == "in" else "out", data))

    def ros_in(t: float, topic: str, msg: Any) -> None:
        executive.observers.emit(RobotInput(t, topic, None, msg))

    return datagram, ros_in


def test_what_arrives_before_the_first_clock_is_stamped_with_it(tmp_path: Path) -> None:
    path = tmp_path / "early.mcap"
    executive = fake_executive()
    with Recorder(path) as recorder:
        attach_all(executive, [recorder])
        datagram, ros_in = wire_of(executive)
        datagram("in", b'{"type":"frontend_idle","seq":1}', 0.0)
        ros_in(0.0, "/docking/state", {"data": "docked"})
        ros_in(0.0, "/clock", encode_clock(1_780_000_000.5))
        executive.clock.set(1_780_000_000.5)
        ros_in(1_780_000_000.5, "/clock", encode_clock(1_780_000_000.6))
    recorder.close()  # idempotent
    datagram("in", b"{}", 1.0)  # after close: ignored
    _, messages = read_all(path)
    assert [(c.topic, from_ns(m.log_time)) for _, c, m in messages] == [
        (FRONTEND_IN, 1_780_000_000.5),
        ("/docking/state", 1_780_000_000.5),
        ("/clock", 1_780_000_000.5),
        ("/clock", 1_780_000_000.6),
    ]


@given(st.floats(min_value=1e7, max_value=4e9))  # ns stamps hold any epoch time exactly
def test_nanosecond_stamps_give_the_clock_time_back(t: float) -> None:
    assert from_ns(to_ns(t)) == t


def test_a_crash_still_leaves_valid_mcap(tmp_path: Path) -> None:
    path = tmp_path / "crash.mcap"
    code = (
        "import sys; from pathlib import Path\n"
        "from frog_bt.live.recording import Recorder\n"
        "from frog_bt.model.events import Datagram\n"
        "r = Recorder(Path(sys.argv[1]))\n"
        'r.on_event(Datagram(1.0, \'out\', b\'{"type":"tour","seq":1}\'))\n'
        "raise RuntimeError('boom')\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code, str(path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert proc.returncode == 1 and "boom" in proc.stderr
    summary, messages = read_all(path)
    assert summary is not None and len(messages) == 1


def test_sigterm_stops_the_run_and_leaves_valid_mcap(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"

    async def main() -> tuple[int | None, float, str]:
        listen = free_udp_port()
        sim = Simulator(
            scenario({"speed": 100.0}),
            rosbridge_port=0,
            frontend_port=0,
            executive=("127.0.0.1", listen),
        )
        await sim.start()
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "frog_bt",
            "run",
            "--sim-time",
            "--checkpoint",
            "none",
            "--record",
            str(path),
            "--quiet",
            "--rosbridge",
            f"ws://127.0.0.1:{sim.rosbridge_port}",
            "--frontend",
            f"127.0.0.1:{sim.frontend_port}",
            "--listen",
            f"127.0.0.1:{listen}",
            cwd=ROOT,
            stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE,
        )
        try:
            await sim.wait_for(lambda r: r.channel == "/GotoWayPoint", timeout=30)
            proc.send_signal(signal.SIGTERM)
            _, err = await asyncio.wait_for(proc.communicate(), 60)  # a hang fails loudly
            return proc.returncode, err.decode()
        finally:
            if proc.returncode is None:
                proc.kill()
                await proc.wait()
            await sim.stop()

    code, err = asyncio.run(main())
    assert code == 0, err
    summary, messages = read_all(path)
    assert summary is not None and summary.statistics.message_count == len(messages)
    topics = {c.topic for _, c, _ in messages}
    assert {"/clock", "/GotoWayPoint", FRONTEND_IN, FRONTEND_OUT, TICK} <= topics

    from frog_bt.cli import main as cli  # the cut-short tour replays identically too

    assert cli(["replay", str(path), "--quiet"]) == 0


def test_what_was_flushed_survives_a_kill(tmp_path: Path) -> None:
    """A chunk is handed to the OS at each flush (every second; here at every drain): a
    copy of the file taken while the recorder runs, as a kill -9 leaves it, has no
    footer, and every message flushed before it is recovered."""
    from frog_bt.recordings.mcapfile import open_recording

    path, copy = tmp_path / "live.mcap", tmp_path / "killed.mcap"

    async def run() -> None:
        executive = fake_executive()
        executive.clock.set(1_780_000_000.0)
        recorder = Recorder(path, flush_every=0.0)
        attach_all(executive, [recorder])
        datagram, _ = wire_of(executive)
        for i in range(1, 31):
            datagram("in", b'{"type":"frontend_idle","seq":%d}' % i, 1_780_000_000.0 + i)
            await background.settled()  # the drain, then the chunk's end it asked for
        copy.write_bytes(path.read_bytes())  # what a kill -9 now would leave
        recorder.close()

    asyncio.run(run())
    recording = open_recording(copy)
    assert recording.recovered.startswith("cut short (no summary or footer): recovered ")
    got = [data for topic, _, data in recording.messages() if topic == FRONTEND_IN]
    assert len(got) == 30 and got[-1] == b'{"type":"frontend_idle","seq":30}'
    assert not open_recording(path).recovered  # the closed file is whole


def test_a_full_chunk_ends_after_the_tick_its_input_calls_for(tmp_path: Path) -> None:
    """Closing a chunk (compressing it, writing its message index) costs the loop up to a
    millisecond at high rates: the drain after an input, and the chunk's end it finds due,
    are background jobs, so the tick the input called for (ready meanwhile) runs first."""
    path = tmp_path / "chunks.mcap"
    seen: list[tuple[str, int]] = []

    async def run() -> None:
        executive = fake_executive()
        executive.clock.set(1_780_000_000.0)
        recorder = Recorder(path, chunk_size=2000)
        attach_all(executive, [recorder])
        datagram, _ = wire_of(executive)
        loop = asyncio.get_running_loop()
        await background.settled()  # the drain, the first chunk's end (primer, tree)
        stream = recorder._stream  # its position: what mcap wrote, buffered or not
        written = stream.tell()

        def an_input() -> None:  # more than a chunk's worth, then the tick it calls for
            for i in range(40):
                datagram("in", b'{"type":"frontend_idle","seq":%d}' % i, 1_780_000_001.0)
            loop.call_soon(lambda: seen.append(("tick", stream.tell() - written)))

        loop.call_soon(an_input)
        await asyncio.sleep(0)  # the input runs, then the tick it calls for
        await background.settled()
        seen.append(("after", stream.tell() - written))
        recorder.close()

    asyncio.run(run())
    assert seen[0] == ("tick", 0)  # the tick ran with the chunk still open
    assert seen[1][0] == "after" and seen[1][1] > 2000  # then the chunk was written
    _, messages = read_all(path)
    assert sum(1 for _, c, _ in messages if c.topic == FRONTEND_IN) == 40
