"""The sans-I/O front-end protocol (CONTRACT §2): bytes and times in, bytes out."""

from __future__ import annotations

import contextlib
import json
import logging
from typing import Any

import msgspec
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frog_bt.errors import DecodeError
from frog_bt.frontend.protocol import (
    MAX_DATAGRAM,
    Endpoint,
    decode_datagram,
    encode_datagram,
)
from frog_bt.model.frontend import (
    COMMANDS,
    EVENTS,
    ContentDone,
    Engagement,
    FollowMe,
    FrontendMessage,
    StartPoi,
    UserPositive,
    Volume,
    decode_message,
    message_fields,
)
from frog_bt.text import inert

PEER = "127.0.0.1"
T0 = 1_700_000_000.0


def executive(**kwargs: Any) -> Endpoint:
    """The executive's side: sends commands, acts on events."""
    return Endpoint(PEER, EVENTS, **kwargs)


def front_end(**kwargs: Any) -> Endpoint:
    """The front end's side: sends events, acts on commands."""
    return Endpoint(PEER, COMMANDS, **kwargs)


def loads(data: bytes) -> dict[str, Any]:
    return json.loads(data)


def ack(seq: int) -> bytes:
    return json.dumps({"type": "ack", "seq": seq}).encode()


def event(type_: str, seq: int, **fields: Any) -> bytes:
    return json.dumps({"type": type_, "seq": seq, **fields}).encode()


# ------------------------------------------------------------------ sending


def test_seq_numbers_start_at_one_and_increase_by_one() -> None:
    ep = executive()
    sent = [loads(ep.send(FollowMe(on=i % 2 == 0), T0 + i)) for i in range(5)]
    assert [d["seq"] for d in sent] == [1, 2, 3, 4, 5]
    assert sent[0] == {"type": "follow_me", "seq": 1, "on": True}
    assert ep.stats.sent == 5 and ep.pending == 5


def test_acks_do_not_use_up_seq_numbers() -> None:
    ep = executive()
    ep.send(FollowMe(on=True), T0)
    ep.receive(event("user_positive", 1), PEER, T0)
    ep.receive(event("user_negative", 2), PEER, T0)
    assert loads(ep.send(FollowMe(on=False), T0))["seq"] == 2


def test_unencodable_message_does_not_use_up_a_seq() -> None:
    ep = executive()
    with pytest.raises(ValueError):
        ep.send(Engagement(level=float("nan")), T0)
    assert loads(ep.send(FollowMe(on=True), T0))["seq"] == 1
    assert ep.stats.sent == 1 and ep.pending == 1


def test_a_message_too_long_is_cut_to_fit_not_lost() -> None:
    ep = executive()
    data = ep.send(StartPoi("x" * MAX_DATAGRAM, "POI1a", "a"), T0)
    assert len(data) <= MAX_DATAGRAM
    sent = loads(data)
    assert sent["seq"] == 1 and sent["waypoint"] == "POI1a" and sent["part"] == "a"
    assert sent["poi"].endswith(f"… ({MAX_DATAGRAM:,} bytes)")


def test_ack_clears_pending() -> None:
    ep = executive()
    message = Volume(percent=80)
    ep.send(message, T0)
    ep.send(FollowMe(on=True), T0)
    received = ep.receive(ack(1), PEER, T0 + 0.1)
    assert received.acked == message
    assert received.message is None and received.reply is None and received.error is None
    assert ep.pending == 1 and ep.stats.acked == 1
    assert ep.poll(T0 + 0.25) == [ep_datagram(2, FollowMe(on=True))]
    # A second ack for the same seq changes nothing.
    assert ep.receive(ack(1), PEER, T0 + 0.3).acked is None
    assert ep.stats.acked == 1


def ep_datagram(seq: int, message: FrontendMessage) -> bytes:
    return encode_datagram(message.type, seq, message_fields(message))


def test_resend_every_quarter_second_then_give_up(caplog: pytest.LogCaptureFixture) -> None:
    ep = executive()
    first = ep.send(FollowMe(on=True), T0)
    sends = [T0]
    for step in range(1, 9):
        due = T0 + 0.25 * step
        assert ep.next_deadline == pytest.approx(due)
        assert ep.poll(due - 0.001) == []
        with caplog.at_level(logging.WARNING, logger="frog_bt.frontend.protocol"):
            out = ep.poll(due)
        if out:
            assert out == [first]  # same bytes, same seq
            sends.append(due)
    assert len(sends) == 8
    assert sends == pytest.approx([T0 + 0.25 * i for i in range(8)])
    assert ep.stats.resent == 7 and ep.stats.unacked == 1 and ep.stats.sent == 1
    assert ep.pending == 0 and ep.next_deadline is None
    assert ep.poll(T0 + 100) == []
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1
    assert "follow_me" in warnings[0].getMessage() and "8 sends" in warnings[0].getMessage()


def test_custom_resend_settings() -> None:
    ep = executive(resend_after=1.0, max_sends=2)
    ep.send(FollowMe(on=True), T0)
    assert ep.poll(T0 + 0.5) == []
    assert len(ep.poll(T0 + 1.0)) == 1
    assert ep.poll(T0 + 2.0) == [] and ep.stats.unacked == 1


def test_never_acking_peer_does_not_block_further_sends() -> None:
    ep = executive()
    for i in range(20):
        data = ep.send(FollowMe(on=True), T0 + 0.1 * i)
        assert loads(data)["seq"] == i + 1
    t = T0
    while ep.pending:
        t += 0.05
        ep.poll(t)
    assert ep.stats.unacked == 20 and ep.stats.sent == 20 and ep.stats.resent == 20 * 7
    assert loads(ep.send(FollowMe(on=False), t))["seq"] == 21


def test_ack_after_some_resends_stops_them() -> None:
    ep = executive()
    ep.send(FollowMe(on=True), T0)
    assert len(ep.poll(T0 + 0.25)) == 1
    assert len(ep.poll(T0 + 0.5)) == 1
    assert ep.receive(ack(1), PEER, T0 + 0.6).acked == FollowMe(on=True)
    assert ep.poll(T0 + 5) == [] and ep.stats.unacked == 0 and ep.stats.resent == 2


# ------------------------------------------------------------------ receiving


def test_event_is_acked_and_returned() -> None:
    ep = executive()
    received = ep.receive(event("content_done", 4, poi="POI1", part="b"), PEER, T0)
    assert received.message == ContentDone(poi="POI1", part="b")
    assert loads(received.reply or b"") == {"type": "ack", "seq": 4}
    assert ep.stats.received == 1


def test_front_end_side_acts_on_commands() -> None:
    fe = front_end()
    received = fe.receive(encode_datagram("volume", 9, {"percent": 50}), PEER, T0)
    assert received.message == Volume(percent=50)
    assert loads(received.reply or b"") == {"type": "ack", "seq": 9}


def test_duplicate_within_window_is_acked_again_but_not_returned() -> None:
    ep = executive()
    assert ep.receive(event("user_positive", 3), PEER, T0).message == UserPositive()
    for dt in (0.25, 5.0, 9.99):
        again = ep.receive(event("user_positive", 3), PEER, T0 + dt)
        assert again.message is None and again.error is None
        assert loads(again.reply or b"") == {"type": "ack", "seq": 3}
    assert ep.stats.duplicates == 3 and ep.stats.received == 1


def test_same_seq_accepted_again_after_window() -> None:
    ep = executive()
    ep.receive(event("user_positive", 3), PEER, T0)
    ep.receive(event("user_negative", 4), PEER, T0 + 5)
    later = ep.receive(event("user_positive", 3), PEER, T0 + 10.01)
    assert later.message == UserPositive()
    assert ep.receive(event("user_negative", 4), PEER, T0 + 10.02).message is None
    assert ep.stats.received == 2 + 0 + 1 and ep.stats.duplicates == 1


def test_custom_dedup_window() -> None:
    ep = executive(dedup_window=1.0)
    ep.receive(event("user_positive", 3), PEER, T0)
    assert ep.receive(event("user_positive", 3), PEER, T0 + 1.5).message == UserPositive()


def test_forget_seen_accepts_a_restarted_peer() -> None:
    ep = executive()
    ep.receive(event("frontend_idle", 1), PEER, T0)
    ep.forget_seen()
    assert ep.receive(event("frontend_idle", 1), PEER, T0 + 1).message is not None


def test_frontend_idle_below_the_highest_seq_is_a_restart() -> None:
    ep = executive()
    for seq, type_ in enumerate(["frontend_idle", "finish_introduction", "user_positive"], 1):
        assert ep.receive(event(type_, seq), PEER, T0 + seq).message is not None
    # Restarted 2 s later: seq 1 again (still within the dedup window), then seqs 2, 3.
    assert ep.receive(event("frontend_idle", 1), PEER, T0 + 5).message is not None
    assert ep.receive(
        event("content_done", 2, poi="POI1", part="a"), PEER, T0 + 6
    ).message == ContentDone("POI1", "a")
    assert ep.receive(event("user_positive", 3), PEER, T0 + 7).message == UserPositive()
    assert ep.stats.peer_restarts == 1 and ep.stats.duplicates == 0


def test_seq_one_after_higher_seqs_is_a_restart_of_any_peer() -> None:
    fe = front_end()  # the front end's side: a restarted executive numbers from 1 again
    for seq in range(1, 13):
        fe.receive(event("follow_me", seq, on=True), PEER, T0 + seq)
    assert fe.receive(event("volume", 1, percent=50), PEER, T0 + 20).message == Volume(50)
    assert fe.receive(event("follow_me", 2, on=False), PEER, T0 + 21).message is not None
    assert fe.stats.peer_restarts == 1


def test_resends_are_not_taken_for_a_restart() -> None:
    ep = executive()
    ep.receive(event("frontend_idle", 1), PEER, T0)
    assert ep.receive(event("frontend_idle", 1), PEER, T0 + 0.25).reply is not None  # ack lost
    ep.receive(event("finish_introduction", 2), PEER, T0 + 1)
    ep.receive(event("user_positive", 3), PEER, T0 + 2)
    got = ep.receive(event("finish_introduction", 2), PEER, T0 + 2.25)  # a late resend
    assert got.message is None and got.reply is not None and loads(got.reply)["seq"] == 2
    assert ep.stats.duplicates == 2 and ep.stats.peer_restarts == 0


def test_only_a_valid_message_from_the_peer_can_signal_a_restart() -> None:
    ep = executive()
    for seq in (1, 2, 3):
        ep.receive(event("user_positive", seq), PEER, T0)
    ep.receive(event("no_such_event", 1), PEER, T0 + 1)  # seq 1, but malformed
    ep.receive(event("frontend_idle", 1), "127.0.0.2", T0 + 1)  # foreign
    assert ep.stats.peer_restarts == 0
    assert ep.receive(event("user_positive", 3), PEER, T0 + 2).message is None  # still seen


@pytest.mark.parametrize("host", ["127.0.0.2", "10.0.0.5", "::1", "localhost"])
def test_foreign_host_dropped_without_reply(host: str) -> None:
    ep = executive()
    ep.send(FollowMe(on=True), T0)
    for data in (event("user_positive", 1), ack(1), b"garbage"):
        received = ep.receive(data, host, T0)
        assert received.message is None and received.reply is None
        assert received.acked is None and received.error is None
    assert ep.stats.foreign == 3 and ep.stats.malformed == 0 and ep.stats.acked == 0
    assert ep.pending == 1


def test_oversized_datagram_is_malformed() -> None:
    ep = executive()
    padding = "x" * MAX_DATAGRAM
    data = event("user_positive", 1, padding=padding)
    assert len(data) > MAX_DATAGRAM
    received = ep.receive(data, PEER, T0)
    assert received.message is None and received.reply is None
    assert isinstance(received.error, DecodeError) and "exceeds" in str(received.error)
    assert ep.stats.malformed == 1


def test_datagram_of_exactly_max_size_is_accepted() -> None:
    ep = executive()
    head = event("user_positive", 1, pad="")
    data = event("user_positive", 1, pad="x" * (MAX_DATAGRAM - len(head)))
    assert len(data) == MAX_DATAGRAM
    assert ep.receive(data, PEER, T0).message == UserPositive()


def test_acks_are_never_acked() -> None:
    ep = executive()
    ep.send(FollowMe(on=True), T0)
    assert ep.receive(ack(1), PEER, T0).reply is None
    assert ep.receive(ack(1), PEER, T0).reply is None  # duplicate ack
    assert ep.receive(ack(99), PEER, T0).reply is None  # ack for nothing
    assert ep.stats.malformed == 0 and ep.stats.received == 0


@pytest.mark.parametrize(
    "data",
    [
        b"",
        b"{",
        b"not json",
        b"\xff\xfe{}",
        b"[1, 2]",
        b'"ack"',
        b"null",
        b'{"type": "user_positive"}',
        b'{"type": "user_positive", "seq": "1"}',
        b'{"type": "user_positive", "seq": -1}',
        b'{"type": "user_positive", "seq": 1.0}',
        b'{"type": "user_positive", "seq": true}',
        b'{"type": 5, "seq": 1}',
        b'{"seq": 1}',
        b'{"type": "engagement", "seq": 1, "level": NaN}',
        b'{"type": "ack", "seq": Infinity}',
        b"[" * 8000,  # nested deeper than the recursion limit
    ],
)
def test_malformed_datagram_is_counted_without_reply(data: bytes) -> None:
    ep = executive()
    received = ep.receive(data, PEER, T0)
    assert received.message is None and received.reply is None
    assert isinstance(received.error, DecodeError)
    assert ep.stats.malformed == 1 and ep.stats.received == 0


def test_unknown_type_is_acked_but_counted_malformed() -> None:
    ep = executive()
    received = ep.receive(event("dance", 5), PEER, T0)
    assert loads(received.reply or b"") == {"type": "ack", "seq": 5}
    assert received.message is None and isinstance(received.error, DecodeError)
    assert ep.stats.malformed == 1 and ep.stats.received == 0
    # A command sent to the executive is just as unknown.
    received = ep.receive(encode_datagram("volume", 6, {"percent": 50}), PEER, T0)
    assert received.reply is not None and ep.stats.malformed == 2


def test_known_type_with_bad_fields_is_acked_but_counted_malformed() -> None:
    ep = executive()
    received = ep.receive(event("content_done", 5, poi="POI1", part="z"), PEER, T0)
    assert received.reply is not None and received.message is None
    assert received.error is not None and received.error.path == ("part",)
    assert ep.stats.malformed == 1


def test_huge_level_is_malformed_not_a_crash() -> None:
    fe = front_end()
    data = b'{"type":"engagement","seq":1,"level":' + b"9" * 400 + b"}"
    received = fe.receive(data, PEER, T0)
    assert received.message is None and received.error is not None
    assert fe.stats.malformed == 1


# ------------------------------------------------------------------ properties

json_scalars = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.text()
    | st.floats(allow_nan=False, allow_infinity=False)
)
json_values = st.recursive(
    json_scalars,
    lambda children: (
        st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=8), children, max_size=4)
    ),
    max_leaves=12,
)
type_names = st.sampled_from([*COMMANDS, *EVENTS, "ack", "", "dance"]) | st.text(max_size=12)
field_names = st.sampled_from(
    [
        "icl",
        "engaged",
        "poi",
        "waypoint",
        "part",
        "level",
        "on",
        "percent",
        "spot",
        "state",
        "reason",
    ]
) | st.text(max_size=8)
json_objects = st.fixed_dictionaries(
    {},
    optional={
        "type": type_names | json_values,
        "seq": st.integers(min_value=-3, max_value=2**40) | json_values,
    },
).flatmap(
    lambda head: st.dictionaries(field_names, json_values, max_size=5).map(
        lambda rest: {**rest, **head}
    )
)


@given(st.binary(max_size=300))
def test_decode_datagram_on_any_bytes(data: bytes) -> None:
    try:
        envelope = decode_datagram(data)
    except DecodeError:
        return
    assert isinstance(envelope.type, str) and isinstance(envelope.seq, int)


@given(json_objects)
def test_decode_datagram_on_any_json_object(obj: dict[str, Any]) -> None:
    data = json.dumps(obj).encode()
    try:
        decoded = decode_datagram(data)
    except DecodeError:
        return
    assert (decoded.type, decoded.seq) == (obj["type"], obj["seq"])
    for table in (COMMANDS, EVENTS):
        with contextlib.suppress(DecodeError):
            decode_message(data, table)


@given(
    st.binary(max_size=300) | json_objects.map(lambda o: json.dumps(o).encode()),
    st.sampled_from([PEER, "127.0.0.2"]),
)
def test_receive_never_raises(data: bytes, host: str) -> None:
    for ep in (executive(), front_end()):
        received = ep.receive(data, host, T0)
        assert received.reply is None or loads(received.reply)["type"] == "ack"
        counted = (
            ep.stats.received
            + ep.stats.malformed
            + ep.stats.foreign
            + ep.stats.duplicates
            + ep.stats.acked
        )
        assert counted <= 1


texts = st.text(max_size=40)
levels = st.none() | st.floats(min_value=-1.0, max_value=1.0) | st.integers(-1, 1)
parts = st.sampled_from(["a", "b"])
messages = st.one_of(
    st.builds(COMMANDS["start_introduction"], icl=st.booleans()),
    st.builds(COMMANDS["ask_tour"], engaged=st.none() | st.booleans()),
    st.builds(COMMANDS["start_poi"], poi=texts, waypoint=texts, part=parts),
    st.builds(COMMANDS["finish_poi"], poi=texts),
    st.builds(COMMANDS["engagement"], level=levels),
    st.builds(COMMANDS["follow_me"], on=st.booleans()),
    st.builds(COMMANDS["volume"], percent=st.integers(0, 100)),
    st.builds(COMMANDS["special_content"], spot=texts),
    st.builds(COMMANDS["projector"], on=st.booleans()),
    st.builds(
        COMMANDS["tour"], state=st.sampled_from(["started", "ended", "aborted"]), reason=texts
    ),
    *(st.just(cls()) for cls in EVENTS.values() if not cls.__struct_fields__),
    st.builds(EVENTS["content_done"], poi=texts, part=parts),
)


def _inert_event(message: FrontendMessage) -> FrontendMessage:
    fields = msgspec.structs.asdict(message)
    return type(message)(**{k: inert(v) if isinstance(v, str) else v for k, v in fields.items()})


@given(messages, st.integers(min_value=0, max_value=50))
def test_round_trip_every_message_type(message: FrontendMessage, skip: int) -> None:
    sender = executive() if message.type in COMMANDS else front_end()
    receiver = front_end() if message.type in COMMANDS else executive()
    sender.next_seq += skip
    data = sender.send(message, T0)
    assert len(data) <= MAX_DATAGRAM
    received = receiver.receive(data, PEER, T0)
    assert received.error is None
    # an event's text is kept inert (escaped, bounded) by the executive that receives it
    expected = message if message.type in COMMANDS else _inert_event(message)
    assert received.message == expected
    assert type(received.message) is type(message)
    assert received.reply is not None
    assert sender.receive(received.reply, PEER, T0).acked == message
    assert sender.pending == 0


@settings(max_examples=50)
@given(
    st.lists(st.sampled_from(["send", "ack", "poll"]), max_size=40),
    st.lists(st.floats(min_value=0.0, max_value=0.6), min_size=40, max_size=40),
)
def test_every_command_is_acked_or_given_up(ops: list[str], steps: list[float]) -> None:
    """Whatever the interleaving, each sent command ends acked or unacked, never lost."""
    ep = executive()
    t = T0
    for op, dt in zip(ops, steps, strict=False):
        t += dt
        if op == "send":
            ep.send(FollowMe(on=True), t)
        elif op == "ack" and ep.next_seq > 1:
            ep.receive(ack(ep.next_seq - 1), PEER, t)
        else:
            ep.poll(t)
    while ep.pending:
        t += 0.25
        ep.poll(t)
    assert ep.stats.acked + ep.stats.unacked == ep.stats.sent == ep.next_seq - 1
