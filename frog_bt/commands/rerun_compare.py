"""Replay in the viewer: the recorded and the replayed commands side by side."""

from __future__ import annotations

from typing import Any


def compare_lanes(rec: Any, replay: Any, site: Any) -> None:
    """In the viewer: the recorded and the replayed commands on two lanes of the same
    timeline (``/log/replay/recorded``, ``/log/replay/replayed``, each with the node
    that sent it), and a marker at the divergence (``/log/replay/divergence``)."""
    import rerun as rr

    from frog_bt.live.telemetry.layout import TICK, TIME, site_ns
    from frog_bt.recordings.commands import describe, differences

    def at(t: float) -> None:
        rec.set_time(TICK, sequence=replay.core.ticks)
        rec.set_time(TIME, timestamp=site_ns(t) / 1e9)

    def command(side: str, c: Any) -> None:
        at(c.t)
        rec.log(
            f"/log/replay/{side}",
            rr.TextLog(f"{side}: {describe(c, site)}  [{c.node or '?'}]", level="INFO"),
        )

    def divergence(d: Any) -> None:
        at(d.t)
        rec.log(
            "/log/replay/divergence",
            rr.TextLog(
                f"divergence, command {d.number}: {differences(d.expected, d.got, site)}",
                level="ERROR",
            ),
        )

    replay.on_command.append(command)
    replay.on_divergence.append(divergence)
