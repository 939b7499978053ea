"""The asyncio front-end link over real loopback UDP, timed by a ManualClock.

No sleeps: resends happen when the test advances the clock, and the test then
awaits the resulting datagram. ``asyncio.wait_for`` timeouts are only a safety
net against a hang.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import socket
from collections.abc import AsyncIterator, Awaitable, Callable
from typing import Any, TypeVar

import pytest

from frog_bt.clock import ManualClock
from frog_bt.frontend.link import FrontendLink, log
from frog_bt.frontend.protocol import MAX_DATAGRAM
from frog_bt.model.frontend import (
    COMMANDS,
    ContentDone,
    FinishIntroduction,
    FollowMe,
    FrontendMessage,
    UserPositive,
    Volume,
)
from frog_bt.warning_limit import WarningLimiter

HOST = "127.0.0.1"
T0 = 1_700_000_000.0
SAFETY = 5.0  # seconds of wall time before a test gives up waiting
T = TypeVar("T")


def run(coro: Callable[[], Awaitable[None]]) -> None:
    async def main() -> None:
        await asyncio.wait_for(coro(), 20)

    asyncio.run(main())


async def within(awaitable: Awaitable[T]) -> T:
    return await asyncio.wait_for(awaitable, SAFETY)


async def until(condition: Callable[[], bool]) -> None:
    """Let the event loop run until ``condition()`` holds (datagrams in flight land)."""

    async def poll() -> None:
        while not condition():
            await asyncio.sleep(0.001)

    await within(poll())


class Tap:
    """Records a link's datagrams (``on_datagram``) and lets a test await them."""

    def __init__(self) -> None:
        self.inbound: asyncio.Queue[bytes] = asyncio.Queue()
        self.outbound: list[bytes] = []

    def __call__(self, direction: str, data: bytes, now: float) -> None:
        if direction == "in":
            self.inbound.put_nowait(data)
        else:
            self.outbound.append(data)


class FakePeer(asyncio.DatagramProtocol):
    """A raw UDP peer that ignores the first ``drop`` datagrams and acks the rest."""

    def __init__(self, drop: int = 0, ack: bool = True) -> None:
        self.drop = drop
        self.ack = ack
        self.datagrams: asyncio.Queue[tuple[dict[str, Any], tuple[str, int]]] = asyncio.Queue()
        self.transport: asyncio.DatagramTransport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]

    def datagram_received(self, data: bytes, addr: tuple[str, int]) -> None:
        obj = json.loads(data)
        self.datagrams.put_nowait((obj, addr))
        if self.drop > 0:
            self.drop -= 1
            return
        if self.ack and obj["type"] != "ack" and self.transport is not None:
            self.transport.sendto(json.dumps({"type": "ack", "seq": obj["seq"]}).encode(), addr)

    def sendto(self, obj: dict[str, Any] | bytes, addr: tuple[str, int]) -> None:
        assert self.transport is not None
        data = obj if isinstance(obj, bytes) else json.dumps(obj).encode()
        self.transport.sendto(data, addr)

    @property
    def port(self) -> int:
        assert self.transport is not None
        return int(self.transport.get_extra_info("sockname")[1])


@contextlib.asynccontextmanager
async def fake_peer(host: str = HOST, **kwargs: Any) -> AsyncIterator[FakePeer]:
    loop = asyncio.get_running_loop()
    transport, peer = await loop.create_datagram_endpoint(
        lambda: FakePeer(**kwargs), local_addr=(host, 0)
    )
    try:
        yield peer
    finally:
        transport.close()


@contextlib.asynccontextmanager
async def started(link: FrontendLink) -> AsyncIterator[FrontendLink]:
    await link.start()
    try:
        yield link
    finally:
        link.close()
        await within(link.wait_closed())


def free_port() -> int:
    """A port free right now (for the bidirectional test, where each side needs the other's)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind((HOST, 0))
        return int(s.getsockname()[1])


# ------------------------------------------------------------------ delivery


def test_commands_delivered_and_acked_between_two_links() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        got: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        front_tap, exec_tap = Tap(), Tap()
        front = FrontendLink(
            (HOST, 0),
            (HOST, 9),
            clock,
            inbound=COMMANDS,
            on_message=got.put_nowait,
            on_datagram=front_tap,
        )
        async with started(front):
            executive = FrontendLink(
                (HOST, 0), (HOST, front.listen_port), clock, on_datagram=exec_tap
            )
            async with started(executive):
                assert executive.listen_port != front.listen_port
                executive.send(Volume(percent=80))
                executive.send(FollowMe(on=True))
                assert await within(got.get()) == Volume(percent=80)
                assert await within(got.get()) == FollowMe(on=True)
                acks = [json.loads(await within(exec_tap.inbound.get())) for _ in range(2)]
                assert acks == [{"type": "ack", "seq": 1}, {"type": "ack", "seq": 2}]
                assert executive.stats.sent == 2 and executive.stats.acked == 2
                assert executive.pending == 0
                assert front.stats.received == 2 and front.stats.foreign == 0
                # The front end acked to the executive's socket, never to its own "peer".
                assert [json.loads(d)["type"] for d in front_tap.outbound] == ["ack", "ack"]
                # Acked: nothing waits for an ack, so no time on the clock resends anything.
                assert executive.next_resend is None
                clock.advance(10)
                assert executive.next_resend is None
                assert executive.stats.resent == 0 and len(exec_tap.outbound) == 2

    run(main)


def test_events_both_ways_between_executive_and_simulated_front_end() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        exec_port, front_port = free_port(), free_port()
        events: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        commands: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        executive = FrontendLink(
            (HOST, exec_port), (HOST, front_port), clock, on_message=events.put_nowait
        )
        front = FrontendLink(
            (HOST, front_port),
            (HOST, exec_port),
            clock,
            inbound=COMMANDS,
            on_message=commands.put_nowait,
        )
        async with started(executive), started(front):
            front.send(UserPositive())
            executive.send(FollowMe(on=False))
            front.send(ContentDone(poi="POI1", part="a"))
            assert await within(events.get()) == UserPositive()
            assert await within(commands.get()) == FollowMe(on=False)
            assert await within(events.get()) == ContentDone(poi="POI1", part="a")
            # Each side numbers its own datagrams from 1.
            assert executive.stats.received == 2 and front.stats.received == 1
            await until(lambda: front.stats.acked == 2 and executive.stats.acked == 1)

    run(main)


def test_ack_goes_to_the_datagram_source_not_the_configured_peer() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        events: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        async with fake_peer() as configured, fake_peer() as sender:
            link = FrontendLink(
                (HOST, 0), (HOST, configured.port), clock, on_message=events.put_nowait
            )
            async with started(link):
                sender.sendto({"type": "user_positive", "seq": 1}, (HOST, link.listen_port))
                assert await within(events.get()) == UserPositive()
                obj, addr = await within(sender.datagrams.get())
                assert obj == {"type": "ack", "seq": 1} and addr[1] == link.listen_port
                assert configured.datagrams.empty()

    run(main)


def test_every_datagram_waiting_is_read_at_the_next_turn_of_the_loop() -> None:
    """A busy event loop turns slowly (a rosbridge backlog, a tick, the recording): read
    one datagram per turn, a fresh event waited behind every stale resend queued before
    it. In the soak (speed 300, a core busy) a ``user_positive`` was read 160 simulated
    seconds after it came, past the answer timeout: the visitor was taken for one who
    gave no answer, and the tour never went on. All that waits is read at once."""

    async def main() -> None:
        clock = ManualClock(T0)
        events: list[FrontendMessage] = []
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as peer:
            peer.bind((HOST, 0))
            link = FrontendLink((HOST, 0), peer.getsockname(), clock, on_message=events.append)
            async with started(link):
                to = (HOST, link.listen_port)
                for _ in range(50):  # the front end resends while its ack is on the way
                    peer.sendto(b'{"type": "finish_introduction", "seq": 2}', to)
                peer.sendto(b'{"type": "user_positive", "seq": 3}', to)
                for _ in range(3):  # three turns of the loop, no time on any clock
                    await asyncio.sleep(0)
                assert events == [FinishIntroduction(), UserPositive()]
                assert link.stats.duplicates == 49 and link.stats.received == 2

    run(main)


# ------------------------------------------------------------------ resends


@pytest.mark.parametrize("drop", [0, 1, 3, 7])
def test_resends_driven_by_the_clock(drop: int) -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        tap = Tap()
        async with fake_peer(drop=drop) as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock, on_datagram=tap)
            async with started(link):
                link.send(FollowMe(on=True))
                first, _ = await within(peer.datagrams.get())
                assert first == {"type": "follow_me", "seq": 1, "on": True}
                for n in range(drop):
                    # Not due yet: a little less than 0.25 s after the last send, the next
                    # resend is still ahead on the clock...
                    due = link.next_resend
                    assert due is not None
                    clock.advance(0.2)
                    assert link.next_resend == due > clock.now()
                    assert link.stats.resent == n
                    # ...and reaching 0.25 s since the last send resends it once.
                    clock.advance(0.05)
                    again, _ = await within(peer.datagrams.get())
                    assert again == first
                    assert link.stats.resent == n + 1
                ack = json.loads(await within(tap.inbound.get()))
                assert ack == {"type": "ack", "seq": 1}
                assert link.stats.acked == 1 and link.pending == 0
                assert link.stats.resent == drop and link.stats.unacked == 0

    run(main)


def test_never_acking_peer_is_given_up_after_eight_sends(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        async with fake_peer(ack=False) as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock)
            async with started(link):
                link.send(FollowMe(on=True))
                seen = [await within(peer.datagrams.get())]
                for _ in range(7):
                    clock.advance(0.25)
                    seen.append(await within(peer.datagrams.get()))
                assert all(obj["seq"] == 1 for obj, _ in seen) and len(seen) == 8
                clock.advance(0.25)
                await until(lambda: link.pending == 0)
                assert link.stats.unacked == 1 and link.stats.resent == 7
                # The link carries on: the next command goes out at once with the next seq.
                link.send(FollowMe(on=False))
                obj, _ = await within(peer.datagrams.get())
                assert obj == {"type": "follow_me", "seq": 2, "on": False}

    with caplog.at_level(logging.WARNING):
        run(main)
    assert any("never acked follow_me" in r.getMessage() for r in caplog.records)


def test_resends_follow_a_clock_that_jumps() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        async with fake_peer(ack=False) as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock, resend_after=1.0)
            async with started(link):
                link.send(Volume(percent=50))
                await within(peer.datagrams.get())
                clock.advance(1.0)
                await within(peer.datagrams.get())
                link.send(Volume(percent=80))  # queued while the task sleeps
                obj, _ = await within(peer.datagrams.get())
                assert obj["seq"] == 2
                clock.advance(60)  # both due: each resent once, not 60 times
                got = sorted([(await within(peer.datagrams.get()))[0]["seq"] for _ in range(2)])
                assert got == [1, 2]
                assert link.stats.resent == 3

    run(main)


def test_resend_task_waits_for_a_sim_clock_that_is_not_ready() -> None:
    async def main() -> None:
        clock = ManualClock()  # not ready, like SimClock before the first /clock
        async with fake_peer(drop=2) as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock)
            async with started(link):
                link.send(FollowMe(on=True))
                await within(peer.datagrams.get())
                for _ in range(3):
                    await asyncio.sleep(0)
                assert link.stats.resent == 0  # the task waits for the clock
                clock.set(T0)  # ready: the command is long overdue, resent at once
                obj, _ = await within(peer.datagrams.get())
                assert obj["seq"] == 1 and link.stats.resent == 1
                clock.advance(0.25)
                obj, _ = await within(peer.datagrams.get())
                assert obj["seq"] == 1 and link.stats.resent == 2
                await until(lambda: link.stats.acked == 1)

    run(main)


# ------------------------------------------------------------------ filtering


def test_datagram_from_a_non_peer_host_is_dropped(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        events: list[FrontendMessage] = []
        tap = Tap()
        try:
            stranger_cm = fake_peer(host="127.0.0.2")
            stranger = await stranger_cm.__aenter__()
        except OSError as exc:
            pytest.skip(f"cannot bind 127.0.0.2: {exc}")
        try:
            async with fake_peer() as friend:
                link = FrontendLink(
                    (HOST, 0), (HOST, friend.port), clock, on_message=events.append, on_datagram=tap
                )
                async with started(link):
                    for seq in (1, 2):
                        stranger.sendto(
                            {"type": "user_positive", "seq": seq}, (HOST, link.listen_port)
                        )
                        await until(lambda seq=seq: link.stats.foreign == seq)
                    assert events == [] and tap.outbound == []  # no ack, no message
                    assert tap.inbound.empty()  # not shown to on_datagram: never recorded
                    friend.sendto({"type": "user_positive", "seq": 1}, (HOST, link.listen_port))
                    await within(tap.inbound.get())
                    assert events == [UserPositive()]
                    obj, _ = await within(friend.datagrams.get())
                    assert obj == {"type": "ack", "seq": 1}
                    assert stranger.datagrams.empty()
        finally:
            await stranger_cm.__aexit__(None, None, None)

    with caplog.at_level(logging.WARNING, logger="frog_bt.frontend.link"):
        run(main)
    foreign = [r for r in caplog.records if "127.0.0.2" in r.getMessage()]
    assert len(foreign) == 1  # rate-limited: one warning for two datagrams


def test_oversized_and_malformed_datagrams_are_counted(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        events: list[FrontendMessage] = []
        tap = Tap()
        async with fake_peer() as peer:
            link = FrontendLink(
                (HOST, 0), (HOST, peer.port), clock, on_message=events.append, on_datagram=tap
            )
            async with started(link):
                big = json.dumps(
                    {"type": "user_positive", "seq": 1, "pad": "x" * MAX_DATAGRAM}
                ).encode()
                assert MAX_DATAGRAM < len(big) < 16384
                peer.sendto(big, (HOST, link.listen_port))
                assert len(await within(tap.inbound.get())) == len(big)  # read whole
                for data in (b"{nope", b'{"type": "dance", "seq": 2}'):
                    peer.sendto(data, (HOST, link.listen_port))
                    await within(tap.inbound.get())
                assert link.stats.malformed == 3 and events == []
                # Only the well-formed unknown type is acked.
                assert [json.loads(d) for d in tap.outbound] == [{"type": "ack", "seq": 2}]

    with caplog.at_level(logging.WARNING, logger="frog_bt.frontend.link"):
        run(main)
    malformed = [r.getMessage() for r in caplog.records if "malformed" in r.getMessage()]
    # one line for the first, the other two told in one line at close
    assert len(malformed) == 2 and "oversized" in malformed[0], malformed
    assert malformed[1] == "2 more malformed suppressed before the end"


def test_handler_exception_does_not_break_the_link(caplog: pytest.LogCaptureFixture) -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        seen: list[FrontendMessage] = []

        def handler(message: FrontendMessage) -> None:
            seen.append(message)
            if len(seen) == 1:
                raise RuntimeError("boom")

        async with fake_peer() as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock, on_message=handler)
            async with started(link):
                for seq in (1, 2):
                    peer.sendto({"type": "frontend_idle", "seq": seq}, (HOST, link.listen_port))
                    obj, _ = await within(peer.datagrams.get())
                    assert obj == {"type": "ack", "seq": seq}
                assert len(seen) == 2

    run(main)
    assert any("handler failed" in r.getMessage() for r in caplog.records)


# ------------------------------------------------------------------ lifecycle


def test_lifecycle() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        async with fake_peer() as peer:
            link = FrontendLink((HOST, 0), (HOST, peer.port), clock)
            with pytest.raises(RuntimeError):
                link.send(FollowMe(on=True))
            with pytest.raises(RuntimeError):
                _ = link.listen_port
            await link.start()
            with pytest.raises(RuntimeError):
                await link.start()
            with pytest.raises(ValueError):
                link.send(FollowMe(on=float("nan")))  # type: ignore[arg-type]
            assert link.stats.sent == 0
            link.close()
            link.close()
            await within(link.wait_closed())
            link.send(FollowMe(on=True))  # dropped, no error
            assert link.stats.sent == 0

    run(main)


def test_peer_given_by_name_is_resolved() -> None:
    async def main() -> None:
        clock = ManualClock(T0)
        events: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        async with fake_peer() as peer:
            link = FrontendLink(
                (HOST, 0), ("localhost", peer.port), clock, on_message=events.put_nowait
            )
            async with started(link):
                peer.sendto({"type": "frontend_idle", "seq": 1}, (HOST, link.listen_port))
                await within(events.get())
                assert link.stats.foreign == 0

    run(main)


@pytest.mark.parametrize("kwargs", [{"resend_after": 0}, {"max_sends": 0}])
def test_invalid_settings(kwargs: dict[str, Any]) -> None:
    with pytest.raises(ValueError):
        FrontendLink((HOST, 0), (HOST, 9), ManualClock(T0), **kwargs)


# ------------------------------------------------------------------ warnings


def test_warning_limiter(caplog: pytest.LogCaptureFixture) -> None:
    wall = [100.0]
    limiter = WarningLimiter(5.0, wall=lambda: wall[0], logger=log)
    with caplog.at_level(logging.WARNING, logger="frog_bt.frontend.link"):
        assert limiter.warn("malformed", "bad 1")
        assert not limiter.warn("malformed", "bad 2")
        assert limiter.warn("foreign", "stranger")  # kinds are limited separately
        wall[0] += 4.9
        assert not limiter.warn("malformed", "bad 3")
        wall[0] += 0.1
        assert limiter.warn("malformed", "bad 4")
        wall[0] += 5
        assert limiter.warn("malformed", "bad 5")
    assert [r.getMessage() for r in caplog.records] == [
        "bad 1",
        "stranger",
        "bad 4 (2 more malformed suppressed)",
        "bad 5",
    ]


def test_the_warnings_held_back_at_the_end_are_told_at_close(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A flood's last bad datagrams are held back by the limiter; closing the link tells
    how many, once, so that nothing is lost without a word."""
    wall = [100.0]
    limiter = WarningLimiter(5.0, wall=lambda: wall[0], logger=log)
    with caplog.at_level(logging.WARNING, logger="frog_bt.frontend.link"):
        limiter.warn("malformed", "bad 1")
        limiter.warn("malformed", "bad 2")
        limiter.warn("malformed", "bad 3")
        limiter.warn("foreign", "stranger")
        assert limiter.flush() == 1
        assert limiter.flush() == 0  # told once
    assert [r.getMessage() for r in caplog.records] == [
        "bad 1",
        "stranger",
        "2 more malformed suppressed before the end",
    ]
