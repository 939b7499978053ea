"""Datagrams in memory: two front-end links talk over a MemoryNet as over UDP."""

from __future__ import annotations

import asyncio

import pytest

from frog_bt.clock import ManualClock
from frog_bt.frontend.link import AddressError, FrontendLink
from frog_bt.frontend.memory import MemoryNet
from frog_bt.model.frontend import COMMANDS, FollowMe, FrontendMessage, UserPositive

HOST = "127.0.0.1"


def test_two_links_deliver_ack_and_resend_over_memory() -> None:
    async def main() -> None:
        net, clock = MemoryNet(), ManualClock(1000.0)
        events: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        commands: asyncio.Queue[FrontendMessage] = asyncio.Queue()
        executive = FrontendLink(
            (HOST, 5006), (HOST, 5005), clock, on_message=events.put_nowait, network=net
        )
        front = FrontendLink(
            (HOST, 5005),
            (HOST, 5006),
            clock,
            inbound=COMMANDS,
            on_message=commands.put_nowait,
            network=net,
        )
        await executive.start()
        await front.start()
        try:
            assert executive.listen_port == 5006
            executive.send(FollowMe(on=True))
            front.send(UserPositive())
            assert await asyncio.wait_for(commands.get(), 5) == FollowMe(on=True)
            assert await asyncio.wait_for(events.get(), 5) == UserPositive()
            await asyncio.wait_for(executive.drain(5), 5)
            assert executive.stats.acked == 1 and executive.pending == 0
            front.close()
            await front.wait_closed()
            executive.send(FollowMe(on=False))  # nobody listens: lost, then resent
            clock.advance(0.3)
            for _ in range(10):
                await asyncio.sleep(0)  # the resend task wakes on the clock
            assert executive.stats.resent >= 1 and net.lost >= 2
        finally:
            executive.close()
            front.close()
            await executive.wait_closed()

    asyncio.run(main())


def test_a_bound_address_is_refused_to_a_second_link() -> None:
    async def main() -> None:
        net, clock = MemoryNet(), ManualClock(0.0)
        first = FrontendLink((HOST, 5006), (HOST, 5005), clock, network=net)
        await first.start()
        try:
            with pytest.raises(AddressError, match="cannot listen there"):
                await FrontendLink((HOST, 5006), (HOST, 5005), clock, network=net).start()
        finally:
            first.close()
            await first.wait_closed()

    asyncio.run(main())
