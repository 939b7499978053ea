"""The one decoder of recordings (:mod:`frog_bt.recordings.reader`): every channel decodes
to the executive's events (:mod:`frog_bt.model.events`), the same Structs; the event
channels of a recording made before (their old shapes) decode to the same events; a
damaged message of each kind is a Bad item counted with its reason and the rest of the
file is still read; any bytes on any channel are an item, never an exception; replay
reports a recording with a damaged robot input or command."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.writer import Writer
from recorded_tour import RecordedTour
from test_own_channels import copy_corrupting

from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.config import Site, load_site
from frog_bt.model import channels
from frog_bt.model.alert import Alert
from frog_bt.model.channels import FRONTEND_IN, FRONTEND_OUT, OWN_TYPES, to_ns
from frog_bt.model.events import (
    AlertChanged,
    Blamed,
    Datagram,
    Doubted,
    Faulted,
    FrontendIn,
    FrontendOut,
    LinksChanged,
    OperatorDone,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.frontend import ContentDone, FrontendIdle, StartPoi
from frog_bt.model.links import Links, LinkStatus
from frog_bt.model.ros import (
    DIAGNOSTICS,
    FACES,
    PEOPLE,
    PERSONS,
    POSE,
    Diagnostics,
    DiagnosticStatus,
    Face,
    FaceData,
    KeyValue,
    PersonDetection,
    PersonDetections,
    Point,
    Pose,
    TrackedPeople,
    TrackedPerson,
)
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.offline.replay import Replay
from frog_bt.offline.report.facts import OWN, ROS_ROLES, read_file
from frog_bt.recordings.mcapfile import RecordingFile, open_recording
from frog_bt.recordings.reader import CLOCK_ROLE, Bad, Item, Primed, Reader

T0 = 1_780_000_000.0  # an epoch time in 2026
SITE = load_site()
POSE_VALUE = Pose(T0, "map", 97.19, 63.02, 0.898316, 0.43934)
Message = tuple[str, float, bytes]  # topic, time, data


def _json(obj: object) -> bytes:
    return msgspec.json.encode(obj)


def _types(site: Site) -> dict[str, str]:
    """Every channel a frog-bt recording has, with its schema name."""
    types = {site.topic(role): topic.type for role, topic in (*INPUTS.items(), *OUTPUTS.items())}
    return {**types, CLOCK.name: CLOCK.type, **OWN_TYPES}


def write(path: Path, messages: list[Message], types: dict[str, str]) -> RecordingFile:
    """An MCAP file as frog-bt writes one (JSON channels, our library name), opened."""
    with path.open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile="", library="frog-bt test")
        ids = {}
        for topic, name in types.items():
            schema = writer.register_schema(name, "jsonschema", b"{}")
            ids[topic] = writer.register_channel(topic, "json", schema)
        for topic, t, data in messages:
            writer.add_message(ids[topic], log_time=to_ns(t), data=data, publish_time=to_ns(t))
        writer.finish()
    return open_recording(path)


def good_messages(site: Site) -> list[Message]:
    """One good message on every channel (and an ack each way), a second apart."""
    topic = site.topic
    faces = FaceData(T0, (Face(7, 0.4, 1.2, True),))
    diagnostics = Diagnostics(
        T0, 73.5, (), (DiagnosticStatus(0, "battery", values=(KeyValue("percentage", "73.5"),)),)
    )
    primer = channels.Primer(
        inputs=[
            channels.PrimerInput(
                topic("docking_state"), T0 - 30.0, msgspec.Raw(b'{"data":"docked"}')
            )
        ],
        frontend_ready=True,
        frontend_out_seqs=[1, 2],
    )
    made = [
        (channels.PRIMER, channels.encode(primer)),
        (CLOCK.name, _json({"clock": {"secs": int(T0), "nsecs": 0}})),
        (topic("pose"), _json(POSE.encode(POSE_VALUE))),
        (topic("response"), b'{"data": 2}'),
        (topic("docking_state"), b'{"data": "undocked"}'),
        (topic("diagnostic"), _json(DIAGNOSTICS.encode(diagnostics))),
        (
            topic("persons"),
            _json(
                PERSONS.encode(PersonDetections(T0, (PersonDetection(3, Point(1.0, 2.0), 181.0),)))
            ),
        ),
        (topic("faces"), _json(FACES.encode(faces))),
        (
            topic("people"),
            _json(PEOPLE.encode(TrackedPeople(T0, (TrackedPerson(3, Point(1.0, 2.0)),)))),
        ),
        (topic("goto"), _json(POSE.encode(POSE_VALUE))),
        (topic("approach"), b'{"data": 3}'),
        (topic("icl"), b'{"data": "start"}'),
        (topic("dock"), b'{"data": "undock"}'),
        (FRONTEND_IN, b'{"type": "frontend_idle", "seq": 1}'),
        (FRONTEND_OUT, b'{"type": "ack", "seq": 1}'),
        (
            FRONTEND_OUT,
            b'{"type": "start_poi", "seq": 3, "poi": "POI1", "waypoint": "POI1b", "part": "a"}',
        ),
        (FRONTEND_IN, b'{"type": "ack", "seq": 3}'),
        (FRONTEND_IN, b'{"type": "content_done", "seq": 2, "poi": "POI1", "part": "a"}'),
        *((channel, channels.encode(event)) for channel, event in EVENTS.items()),
        (channels.TREE, channels.encode(channels.Tree("BehaviorTree.CPP v4", "t", "<r/>"))),
    ]
    return [(name, T0 + i, data) for i, (name, data) in enumerate(made)]


LINKS = Links(LinkStatus.CONNECTED, LinkStatus.ACKING, LinkStatus.SIM)
EVENTS = {  # one event of each kind recorded on our channels, as the executive tells it
    channels.TICK: Ticked(T0 + 0.1, 1, "RUNNING"),
    channels.BLAME: Blamed(T0 + 0.1, "start_poi", "tour.yaml:3 Play", {"stop": "POI1"}),
    channels.OPERATOR: OperatorDone(T0 + 0.1, 4, "skip", True, "ok", by="console"),
    channels.ALERT: AlertChanged(T0 + 0.1, Alert("a1", "fault", "x", "raised", T0)),
    channels.DOUBT: Doubted(T0 + 0.1, 2, "SHOP", "arrival at POI2 heard late: ignored", "POI2"),
    channels.FAULT: Faulted(T0 + 0.1, "node X", "its tick", "ValueError: x", 3),
    channels.LINKS: LinksChanged(T0 + 0.1, LINKS),
}

BAD: dict[str, tuple[bytes, str]] = {  # a damaged message of each kind: data, its reason
    "pose": (b'{"pose": {"position": {"x": 1, "y": 2}}}', "pose.orientation: missing field"),
    "response": (b"not json", "not JSON"),
    "diagnostic": (
        b'{"status": [{"level": 2, "name": "battery", "values": [{"key": '
        b'"percentage", "value": "lots"}]}]}',
        "status[0].values[0].value: expected a number, got 'lots'",
    ),
    "goto": (b"[1, 2]", "expected `object`, got `array`"),
    "approach": (b'{"data": "seven"}', "data: expected `int`, got `str`"),
    FRONTEND_IN: (b'{"type": "user_maybe", "seq": 4}', "type"),
    FRONTEND_OUT: (b'{"type": "start_poi", "seq": 5, "poi": "POI1"}', "missing field"),
    channels.TICK: (
        b'{"type": "Ticked", "t": 1.0, "tick": "one", "status": "RUNNING"}',
        "tick: expected `int`",
    ),
    channels.ALERT: (b'{"id": "a"}', "missing field"),
    CLOCK.name: (b'{"clock": {"secs": 1}}', "clock: expected {secs, nsecs}"),
}


def _topic(key: str) -> str:
    return SITE.topic(key) if key in INPUTS or key in OUTPUTS else key


def test_every_channel_decodes_to_the_executives_events(tmp_path: Path) -> None:
    types = {**_types(SITE), "/rosout": "rosgraph_msgs/Log"}
    messages = [*good_messages(SITE), ("/rosout", T0 + 99, b'{"msg": "hello"}')]
    reader = Reader(SITE)
    items = list(reader.read(write(tmp_path / "good.mcap", messages, types)))
    assert reader.tally.count == 0 and not any(isinstance(i, Bad) for _, i in items)
    assert reader.tally.unread == {"/rosout": 1}  # no declaration for it: counted, unread
    times = [t for t, _ in items]
    assert times == sorted(times)  # log-time order
    assert sorted(set(times)) == [t for _, t, _ in messages[:-1]]  # every message

    inputs = {reader.roles[i.topic]: i for _, i in items if isinstance(i, RobotInput)}
    assert set(inputs) == {*INPUTS, CLOCK_ROLE}
    assert inputs["pose"].value == POSE_VALUE
    raw = inputs["pose"].raw
    assert raw is not None and msgspec.json.decode(raw) == POSE.encode(POSE_VALUE)  # as recorded
    assert (inputs["response"].value, inputs["docking_state"].value) == (2, "undocked")
    assert inputs[CLOCK_ROLE].value == T0
    diagnostics = inputs["diagnostic"].value
    assert isinstance(diagnostics, Diagnostics) and diagnostics.battery == 73.5
    for role, kind in (
        ("faces", FaceData),
        ("persons", PersonDetections),
        ("people", TrackedPeople),
    ):
        assert isinstance(inputs[role].value, kind)

    commands = {i.role: i for _, i in items if isinstance(i, RobotCommand)}
    assert set(commands) == set(OUTPUTS)
    assert commands["goto"].value == POSE_VALUE
    assert commands["goto"].msg == POSE.encode(POSE_VALUE)
    assert [commands[r].value for r in ("approach", "icl", "dock")] == [3, "start", "undock"]

    # every datagram as it crossed; each new event or command after its datagram
    frontend = [
        (i.direction, i.data) if isinstance(i, Datagram) else i
        for _, i in items
        if isinstance(i, Datagram | FrontendIn | FrontendOut)
    ]
    datagrams = [
        (topic, data) for topic, _, data in messages if topic in (FRONTEND_IN, FRONTEND_OUT)
    ]
    assert frontend == [
        ("in", datagrams[0][1]),
        FrontendIn(T0 + 13, FrontendIdle()),
        ("out", datagrams[1][1]),  # an ack
        ("out", datagrams[2][1]),
        FrontendOut(T0 + 15, StartPoi("POI1", "POI1b", "a")),
        ("in", datagrams[3][1]),  # an ack
        ("in", datagrams[4][1]),
        FrontendIn(T0 + 17, ContentDone("POI1", "a")),
    ]

    # our channels: the events as the executive told them, each on its channel
    own = {t: i for t, i in items if isinstance(i, tuple(type(e) for e in EVENTS.values()))}
    assert list(own.values()) == list(EVENTS.values())
    (tree,) = [i for _, i in items if isinstance(i, channels.Tree)]
    assert tree.xml == "<r/>"
    ((t, primed),) = [(t, i) for t, i in items if isinstance(i, Primed)]
    assert primed.primer.frontend_out_seqs == [1, 2] and primed.primer.frontend_ready
    assert [(reader.roles[i.topic], i.value, i.t) for i in primed.inputs] == [
        ("docking_state", "docked", T0 - 30.0)
    ]  # at the time it was received
    assert t == T0


OLD = {  # the same events as a recording made before recorded them (old schema, old shape)
    channels.TICK: ("frog_bt/Tick", b'{"tick":1,"status":"RUNNING"}'),
    channels.BLAME: (
        "frog_bt/Blame",
        b'{"channel":"start_poi","node":"tour.yaml:3 Play","reads":{"stop":"POI1"}}',
    ),
    channels.OPERATOR: (
        "frog_bt/Operator",
        b'{"tick":4,"command":"skip","ok":true,"text":"ok","id":"","by":"console"}',
    ),
    channels.ALERT: (
        "frog_bt/Alert",
        b'{"id":"a1","kind":"fault","text":"x","state":"raised","since":1780000000.0}',
    ),
    channels.DOUBT: (
        "frog_bt/Doubt",
        b'{"code":2,"goal":"SHOP","why":"arrival at POI2 heard late: ignored","answers":"POI2"}',
    ),
    channels.FAULT: (
        "frog_bt/Fault",
        b'{"where":"node X","what":"its tick","error":"ValueError: x","count":3}',
    ),
    channels.LINKS: (
        "frog_bt/Links",
        b'{"rosbridge":"connected","frontend":"acking","clock":"/clock"}',
    ),
}


def test_an_old_recordings_event_channels_decode_to_the_same_events(tmp_path: Path) -> None:
    """Before the events were recorded as themselves, each had a shape of its own (no time,
    no tag) under another schema name: read as the same event, its time the log's."""
    types = {channel: schema for channel, (schema, _) in OLD.items()}
    messages = [(channel, T0 + 0.1, data) for channel, (_, data) in OLD.items()]
    reader = Reader(SITE)
    items = [i for _, i in reader.read(write(tmp_path / "old.mcap", messages, types))]
    assert items == list(EVENTS.values()) and reader.tally.count == 0
    damaged = [(channels.TICK, T0, b'{"tick": "one", "status": "RUNNING"}')]
    (bad,) = [i for _, i in Reader(SITE).read(write(tmp_path / "bad.mcap", damaged, types))]
    assert isinstance(bad, Bad) and bad.reason.startswith("tick: expected `int`")


def test_a_recording_made_by_the_code_before_reads_and_replays_identical() -> None:
    """A recording ``frog-bt demo --scenario undock_fails`` made before the events were
    recorded as themselves (tests/data): it reads whole and replays identical."""
    path = Path(__file__).parents[1] / "data" / "recorded-v0.1.0-undock_fails.mcap"
    recording = open_recording(path)
    assert recording.types[channels.TICK] == "frog_bt/Tick"  # the old shapes
    reader = Reader(SITE)
    items = [i for _, i in reader.read(recording)]
    assert reader.tally.count == 0
    ticks = [i for i in items if isinstance(i, Ticked)]
    assert [i.tick for i in ticks] == list(range(1, len(ticks) + 1)) and len(ticks) > 50
    assert {type(i) for i in items} >= {Blamed, AlertChanged, LinksChanged, FrontendOut}
    result = Replay(path, SITE, load_tree(site=SITE)).run()
    assert result.identical and result.exact and not result.bad_count
    assert (result.ticks, result.ros_commands, result.frontend_commands) == (len(ticks), 3, 2)
    assert result.alerts == 1


def test_a_damaged_message_of_each_kind_is_counted_and_the_rest_still_read(tmp_path: Path) -> None:
    good = good_messages(SITE)
    bad_primer = channels.encode(
        channels.Primer(
            inputs=[
                channels.PrimerInput(SITE.topic("response"), T0 - 5, msgspec.Raw(b'{"data": 1.5}')),
                channels.PrimerInput(
                    SITE.topic("docking_state"), T0 - 4, msgspec.Raw(b'{"data": "docked"}')
                ),
            ]
        )
    )
    damaged = [(_topic(key), T0 + 100 + i, data) for i, (key, (data, _)) in enumerate(BAD.items())]
    damaged.append((channels.PRIMER, T0 + 200, bad_primer))
    later = [(topic, t + 300, data) for topic, t, data in good]
    reader = Reader(SITE, keep=5)
    items = list(reader.read(write(tmp_path / "bad.mcap", [*good, *damaged, *later], _types(SITE))))

    bad = [i for _, i in items if isinstance(i, Bad)]
    assert [(b.channel, b.t) for b in bad] == [
        *((topic, t) for topic, t, _ in damaged[:-1]),
        (channels.PRIMER, T0 + 200),
    ]
    for item, (_, reason) in zip(bad, BAD.values(), strict=False):
        assert reason in item.reason, (item.channel, item.reason)
    assert bad[-1].reason == "inputs[0] (/FROG_response): data: expected `int`, got `float`"
    (primed,) = [i for t, i in items if isinstance(i, Primed) and t == T0 + 200]
    assert [i.value for i in primed.inputs] == ["docked"]  # the good entry is kept

    tally = reader.tally
    assert tally.count == len(BAD) + 1
    assert tally.by_channel[SITE.topic("pose")] == 1 and tally.by_channel[FRONTEND_IN] == 1
    assert [b.channel for b in tally.first] == [b.channel for b in bad[:5]]  # 5 kept
    assert tally.lines(T0)[0] == f"{SITE.topic('pose')} at +{100.0:.1f} s: {bad[0].reason}"
    good_after = {t for t, i in items if t >= T0 + 300 and not isinstance(i, Bad)}
    assert good_after == {t for _, t, _ in later}  # the rest of the file is still read


class _Messages(RecordingFile):
    """A recording's channels and messages without a file: the reader's seam."""

    def __init__(self, types: dict[str, str], messages: list[Message]) -> None:
        super().__init__(Path("fake.mcap"), types, 0, 0)
        self._messages = messages

    def messages(self) -> Iterator[tuple[str, int, bytes]]:
        for topic, t, data in self._messages:
            yield topic, to_ns(t), data


TOPICS = sorted(_types(SITE))


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(TOPICS),
            st.binary(max_size=80)
            | st.sampled_from(
                [
                    b'{"data": 1}',
                    b'{"type": "ack", "seq": 1}',
                    b'{"tick": 1, "status": "RUNNING"}',
                    b"{}",
                    b'{"inputs": [{"topic": "/FROG_response", "t": 1, "msg": {"data": "x"}}]}',
                ]
            ),
        ),
        max_size=8,
    )
)
def test_any_bytes_on_any_channel_are_an_item_never_an_exception(
    messages: list[tuple[str, bytes]],
) -> None:
    reader = Reader(SITE)
    recording = _Messages(
        _types(SITE), [(topic, T0 + i, data) for i, (topic, data) in enumerate(messages)]
    )
    items: list[tuple[float, Item]] = list(reader.read(recording))
    assert sum(isinstance(i, Bad) for _, i in items) == reader.tally.count
    assert {t for t, _ in items} == {T0 + i for i in range(len(messages))}  # each one read


def test_replay_reports_a_damaged_robot_input_and_command(
    tour: RecordedTour, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    site = load_site()
    once = tmp_path / "input.mcap"
    copy_corrupting(tour.path, once, site.topic("docking_state"), b'{"data": 7}', nth=2)
    result = Replay(once, site, load_tree(site=site)).run()
    assert result.bad_count == len(result.bad) == 1
    assert result.bad[0].startswith(f"{site.topic('docking_state')} at +")
    assert result.bad[0].endswith("data: expected `str`, got `int`")

    twice = tmp_path / "command.mcap"
    copy_corrupting(once, twice, site.topic("goto"), b"\x00 not json", nth=1)
    result = Replay(twice, site, load_tree(site=site)).run()  # replay.py crashed here
    assert result.bad_count == 2
    assert result.bad[1].startswith(f"{site.topic('goto')} at +")
    assert "not JSON" in result.bad[1]
    assert result.divergence is not None  # the recorded goal is missing: said, not guessed
    assert main(["replay", str(twice), "--quiet"]) == 1
    out = capsys.readouterr().out
    assert "note: 2 bad message(s) in the recording, skipped:" in out


def test_the_report_counts_damaged_messages_and_reads_past_them(tmp_path: Path) -> None:
    good = good_messages(SITE)
    damaged = [(_topic(key), T0 + 100 + i, data) for i, (key, (data, _)) in enumerate(BAD.items())]
    path = tmp_path / "bad.mcap"
    write(path, [*good, *damaged], _types(SITE))
    facts = read_file(str(path), SITE)
    assert not facts.error
    read = {SITE.topic(role) for role in ROS_ROLES} | set(OWN)  # the channels it reads
    assert facts.bad == sum(topic in read for topic, _, _ in damaged)
    assert facts.bad_first[0].startswith(f"{SITE.topic('pose')} at +100.0 s: ")
    (piece,) = facts.pieces
    assert [(s.poi, s.waypoint) for s in piece.stops if s.parts] == [("POI1", "POI1b")]


def test_no_twins_of_the_events_remain() -> None:
    """One family of facts: the recorder writes the events, the reader gives them back;
    no channel Struct or reader record mirrors one of them."""
    from frog_bt.model import events
    from frog_bt.recordings import reader

    for name in ("Tick", "Blame", "Operator", "Doubt", "Fault", "Links"):
        assert not hasattr(channels, name), f"channels.{name} mirrors an event"
    for name in ("Record", "Own", "FrontendAck", "OwnMessage", "RosValue"):
        assert not hasattr(reader, name), f"reader.{name} is a record family of its own"
    for name in ("RobotInput", "RobotCommand", "FrontendIn", "FrontendOut"):
        assert getattr(reader, name, None) in (None, getattr(events, name))
    names = "Tick|Blame|Operator|Doubt|Fault|Links|Own|FrontendAck|FrontendIn|FrontendOut"
    twin = re.compile(rf"^class ({names}|Robot\w+)\((msgspec\.)?Struct\b", re.M)
    package = Path(events.__file__).parents[1]
    found = [
        p
        for p in package.rglob("*.py")
        if p.name != "events.py" and twin.search(p.read_text(encoding="utf-8"))
    ]
    assert not found, found
