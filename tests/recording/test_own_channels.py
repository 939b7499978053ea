"""frog-bt's own channels: they hold the executive's events as themselves (one tagged
union); operator commands are recorded and applied again by replay at the same tick
(identical), and a bad message of our channels is counted and reported with its reason,
never dropped silently."""

from __future__ import annotations

import asyncio
import shutil
from pathlib import Path

import msgspec
import pytest
from mcap.reader import make_reader
from mcap.writer import Writer
from recorded_tour import scenario

from frog_bt import resources
from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.live.recording import Recorder
from frog_bt.model import channels
from frog_bt.model.events import Blamed, OperatorDone, Recorded, Ticked
from frog_bt.offline.replay import Replay
from frog_bt.recordings.mcapfile import open_recording
from frog_bt.recordings.reader import Reader
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.observer import attach_all


def is_(channel: str, **fields: object):  # type: ignore[no-untyped-def]
    return lambda r: (
        r.direction == "in"
        and r.channel == channel
        and all(r.payload.get(k) == v for k, v in fields.items())
    )


async def _record_with_commands(path: Path) -> list[tuple[bool, str]]:
    site = load_site()
    recorder = Recorder(path)
    rehearsal = Rehearsal(
        scenario(), site=site, prepare=lambda exe: attach_all(exe, [recorder]), memory=True
    )
    answers = []
    try:
        async with rehearsal:
            core = rehearsal.executive.core
            await rehearsal.sim.wait_for(is_("start_poi", poi="POI2", part="a"), 60)
            answers.append(core.command(Command.SKIP))
            await rehearsal.sim.wait_for(is_("start_poi", poi="POI4", part="a"), 60)
            answers.append(core.command(Command.PAUSE))
            answers.append(core.command(Command.PAUSE))  # refused: recorded too
            await rehearsal.sim.clock.sleep_until(rehearsal.sim.clock.now() + 40.0)
            answers.append(core.command(Command.RESUME))
            outcome = await rehearsal.finish(60.0)
            assert outcome.code == 0, outcome.reason
    finally:
        recorder.close()
    return [(a.ok, a.text) for a in answers]


@pytest.fixture(scope="module")
def commanded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("operator") / "commanded.mcap"
    answers = asyncio.run(_record_with_commands(path))
    assert [ok for ok, _ in answers] == [True, True, False, True]
    return path


def test_a_tour_with_operator_commands_replays_identically(
    commanded: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    result = Replay(commanded, load_site(), load_tree(site=load_site())).run()
    assert result.identical, result.divergence
    assert result.operator_commands == 4
    assert main(["replay", str(commanded), "--quiet"]) == 0
    assert ", 4 operator commands" in capsys.readouterr().out


def test_without_the_skip_handler_the_replayed_answer_differs(
    commanded: Path, tmp_path: Path
) -> None:
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    visit = trees / "visit_poi.yaml"
    lines = visit.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if "type: OperatorSkip" in line)
    # the OperatorSkip decorator and its three lines go; its child moves up one level
    body = [line[2:] if line.startswith("      ") else line for line in lines[start + 4 :]]
    visit.write_text("\n".join([*lines[:start], *body]) + "\n")
    tree = load_tree(trees / "tour.yaml", load_site())
    result = Replay(commanded, load_site(), tree).run()
    div = result.divergence
    assert div is not None and div.expected is not None and div.got is not None
    assert div.expected.channel == channels.OPERATOR
    assert div.expected.payload == {
        "command": "skip",
        "ok": True,
        "did": "skipping POI2: on to the next stop",
    }
    assert div.got.payload["ok"] is False


def test_our_channels_hold_the_events_as_themselves(commanded: Path) -> None:
    """Each message of an event channel is one of the executive's events, as it told it:
    its raw bytes decode with the union's decoder (msgspec's tagged union), under the
    event's own schema name; the reader gives back the same events."""
    union = msgspec.json.Decoder(Recorded)
    got: dict[str, list[Recorded]] = {}
    told: list[Recorded] = []  # in log-time order
    with commanded.open("rb") as f:
        for schema, chan, message in make_reader(f).iter_messages():
            if chan.topic in channels.EVENT_CHANNELS.values():
                event = union.decode(message.data)
                assert schema is not None and schema.name == f"frog_bt/{type(event).__name__}"
                assert channels.EVENT_CHANNELS[type(event)] == chan.topic
                assert channels.to_ns(event.t) <= message.log_time  # stamped when told
                got.setdefault(chan.topic, []).append(event)
                told.append(event)
    operator = [e for e in got[channels.OPERATOR] if isinstance(e, OperatorDone)]
    assert [(e.command, e.ok) for e in operator] == [
        ("skip", True),
        ("pause", True),
        ("pause", False),
        ("resume", True),
    ]
    ticks = [e.tick for e in got[channels.TICK] if isinstance(e, Ticked)]
    assert ticks == list(range(1, len(got[channels.TICK]) + 1))
    assert all(isinstance(e, Blamed) for e in got[channels.BLAME])
    site = load_site()
    read = [e for _, e in Reader(site).read(open_recording(commanded)) if isinstance(e, Recorded)]
    assert read == told  # the reader gives back the same events


def copy_corrupting(src: Path, dst: Path, channel: str, data: bytes, nth: int = 1) -> None:
    """``src`` rewritten to ``dst`` with the ``nth`` message of ``channel`` replaced."""
    with src.open("rb") as f_in, dst.open("wb") as f_out:
        reader = make_reader(f_in)
        writer = Writer(f_out)
        writer.start()
        schemas: dict[int, int] = {}
        chans: dict[int, int] = {}
        seen = 0
        for schema, chan, message in reader.iter_messages(log_time_order=False):
            if chan.id not in chans:
                if schema is not None and schema.id not in schemas:
                    schemas[schema.id] = writer.register_schema(
                        schema.name, schema.encoding, schema.data
                    )
                chans[chan.id] = writer.register_channel(
                    chan.topic,
                    chan.message_encoding,
                    schemas[schema.id] if schema is not None else 0,
                )
            payload = message.data
            if chan.topic == channel:
                seen += 1
                if seen == nth:
                    payload = data
            writer.add_message(
                chans[chan.id], message.log_time, payload, message.publish_time, message.sequence
            )
        writer.finish()


def test_a_bad_message_of_our_channels_is_counted_and_reported(
    commanded: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.mcap"
    blame = b'{"type": "Blamed", "t": 1.0, "channel": 5, "node": "x"}'
    copy_corrupting(commanded, bad, channels.BLAME, blame, nth=3)
    result = Replay(bad, load_site(), load_tree(site=load_site())).run()
    assert result.identical  # a blame only explains a command: the replay goes on
    assert result.bad_count == 1
    assert len(result.bad) == 1
    assert result.bad[0].startswith("/frog_bt/blame at +")
    assert result.bad[0].endswith("channel: expected `str`, got `int`")
    assert main(["replay", str(bad), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "note: 1 bad message(s) in the recording, skipped:" in out
