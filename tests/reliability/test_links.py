"""The operator's view of the links: each link's state over time, in the status line and
the rerun viewer, so that "the robot waited because the front end was silent" shows."""

from __future__ import annotations

import asyncio
from pathlib import Path

from harness import TourRun

from frog_bt.live.telemetry import Telemetry
from frog_bt.model.events import LinksChanged
from frog_bt.model.links import Links, frontend_state
from frog_bt.runtime.observer import attach_all, listen


def test_front_end_state_needs_a_command_waiting_and_a_quiet_peer() -> None:
    assert frontend_state(None, None, 10.0) == "not heard"
    assert frontend_state(None, 1.0, 10.0) == "acking"  # nothing waits: quiet is fine
    assert frontend_state(9.5, 1.0, 10.0) == "acking"  # sent just now: not yet silent
    assert frontend_state(7.0, 7.5, 10.0) == "acking"  # heard since it was sent
    assert frontend_state(7.0, 1.0, 10.0) == "silent"  # waited 3 s, nothing since
    assert frontend_state(7.0, None, 10.0) == "silent"


def test_an_outage_and_a_silent_front_end_show_as_link_states(tmp_path: Path) -> None:
    """The rosbridge server goes away and comes back; later the front end hangs for 20 s
    while content plays: the links tap sees rosbridge connected → reconnecting →
    connected and the front end acking → silent → acking; the status line says so
    while it lasts; the .rrd has a lane per link with those states."""
    rrd = tmp_path / "links.rrd"
    seen: list[tuple[float, Links]] = []
    lines: list[str] = []

    async def main() -> None:
        async with TourRun({"speed": 200}) as run:
            sim, exe = run.sim, run.executive
            telemetry = Telemetry.open(f"save:{rrd}", exe.site, exe.core.tree)
            attach_all(exe, [telemetry])

            def on_links(event: LinksChanged) -> None:
                seen.append((event.t, event.links))
                lines.append(exe.status_text())

            listen(exe, on_links, LinksChanged)
            await sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 30)
            await run.outage(until=asyncio.sleep(0))
            await sim.wait_for(lambda r: r.direction == "in" and r.channel == "start_poi", 30)
            sim.silence_frontend(20.0)
            await run.finish(60)
            telemetry.close()

    asyncio.run(main())
    rosbridge = [links.rosbridge for _, links in seen]
    frontend = [links.frontend for _, links in seen]
    lost = rosbridge.index("reconnecting")
    assert rosbridge[lost + 1] == "connected" and rosbridge[-1] == "closed"  # at the exit
    assert "silent" in frontend and "acking" in frontend[frontend.index("silent") :]
    silent_at = frontend.index("silent")
    assert "front end silent" in lines[silent_at]
    assert seen[-1][1].clock == "/clock"

    from rerun.chunk import RrdReader

    lanes: dict[str, list[str]] = {}
    for chunk in RrdReader(rrd).stream():
        if chunk.entity_path.startswith("/links/") and not chunk.is_static:
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.endswith(":state"):
                    lanes.setdefault(chunk.entity_path, []).extend(
                        s for row in batch.column(name).to_pylist() for s in row
                    )
    assert "silent" in lanes["/links/frontend"] and "acking" in lanes["/links/frontend"]
    assert "reconnecting" in lanes["/links/rosbridge"]
