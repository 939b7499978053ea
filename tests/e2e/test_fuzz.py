"""Fuzzing from the robot's side: a running executive, its real rosbridge and UDP links,
and generated traffic on every input topic and front-end event (hypothesis).

Each example is one whole tour against the simulator on sim time, with a generated
stream of extra input injected as it runs: valid shapes with extreme values, wrong
types, missing fields, huge strings with control characters, NaN and infinities,
answers out of order and for no goal or the wrong one, front-end events out of turn,
duplicated and malformed. Properties:

* the executive never exits;
* the tour ends docked at the charger, or holding with ``help`` for a person;
* ``dock`` never goes out while the (simulated, true) robot is away from the dock;
* the log stays one line per event: no record quotes a newline or a control character.

What the robot says of itself consistently cannot be caught, so the generated traffic
never claims the robot is docked, nor puts it within 10 m of the dock: a robot that lies
about its own pose and its charger is outside what any executive can check.

The short profile runs in the README's test command; ``FROG_BT_FUZZ=long`` runs the long
one (the count is in docs/RELIABILITY.md).
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import os
import socket
from typing import Any

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from tour import Running, after_ticks

from frog_bt.model import keys
from frog_bt.model.outcomes import TourState
from frog_bt.model.wire import INPUTS

LONG = os.environ.get("FROG_BT_FUZZ") == "long"
EXAMPLES = 150 if LONG else 3
TOPICS = {role: inp.name for role, inp in INPUTS.items()}
SHOP = (95.89384, 17.22943)

# ------------------------------------------------------------------ values

nasty_text = st.one_of(
    st.text(max_size=40),
    st.sampled_from(
        ["\x1b]0;pwned\x07", "\x1b[31mred\x1b[0m", "a\nWARNING frog_bt.alerts: forged", "\u202e"]
    ),
    st.integers(1000, 20_000).map(lambda n: ("Traceback\n\x1b[2J" * (n // 16 + 1))[:n]),
)
number = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(2**63), 2**63),
    st.sampled_from([0, -1, 1e308, -1e-308, 2**31, -(2**31) - 1]),
)
anything = st.recursive(
    st.none() | st.booleans() | number | nasty_text,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)


coordinate = st.one_of(st.floats(-1e6, 1e6), number)
far = st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)).filter(
    lambda xy: math.hypot(xy[0] - SHOP[0], xy[1] - SHOP[1]) > 10
)
garbage_xy = st.tuples(number, number).filter(
    lambda xy: not all(isinstance(v, float) and math.isfinite(v) for v in xy)
)
HEADER = {"stamp": {"secs": 1780000000, "nsecs": 0}, "frame_id": "map"}
pose = st.one_of(far, garbage_xy).map(
    lambda xy: {
        "header": HEADER,
        "pose": {
            "position": {"x": xy[0], "y": xy[1], "z": 0.0},
            "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
        },
    }
)
response = st.builds(lambda code: {"data": code}, st.one_of(st.integers(-3, 8), number, nasty_text))
docking = st.builds(
    lambda word: {"data": word},
    st.one_of(st.sampled_from(["failed", "docking", "undocking", "DOCKED", ""]), nasty_text),
)
diagnostic = st.builds(
    lambda level, name, message, pct: {
        "header": {"stamp": {"secs": 1, "nsecs": 0}, "frame_id": ""},
        "status": [
            {
                "level": level,
                "name": name,
                "message": message,
                "hardware_id": name,
                "values": [{"key": "percentage", "value": pct}],
            },
        ],
    },
    st.one_of(st.integers(-1, 5), number),
    st.one_of(st.just("battery"), nasty_text),
    nasty_text,
    st.one_of(st.sampled_from(["5", "150", "-3", "NaN", "inf", "1e400"]), nasty_text),
)
persons = st.builds(
    lambda pid, x, y, o: {
        "header": HEADER,
        "persons": [{"id": pid, "position": {"x": x, "y": y, "z": 0.0}, "orientation": o}],
    },
    st.one_of(st.integers(-5, 10), st.integers(2**31, 2**40)),
    coordinate,
    coordinate,
    number,
)
faces = st.builds(
    lambda fid, e, d: {
        "header": {},
        "faces": [{"id": fid, "engagement": e, "distance": d, "facing": True}],
    },
    st.integers(0, 10),
    number,
    number,
)
ros_message = st.one_of(
    st.tuples(st.just("response"), response),
    st.tuples(st.just("pose"), pose),
    st.tuples(st.just("docking_state"), docking),
    st.tuples(st.just("diagnostic"), diagnostic),
    st.tuples(st.just("persons"), persons),
    st.tuples(st.just("faces"), faces),
    st.tuples(st.sampled_from(list(TOPICS)), anything),  # wrong types, missing fields
)
EVENT_TYPES = [
    "frontend_idle",
    "finish_introduction",
    "user_positive",
    "user_negative",
    "content_done",
]
datagram = st.one_of(
    st.builds(
        lambda t, seq, poi, part: {"type": t, "seq": seq, "poi": poi, "part": part},
        st.sampled_from(EVENT_TYPES),
        st.one_of(st.integers(0, 50), number),
        st.one_of(st.sampled_from(["POI1", "POI2", "POI3"]), nasty_text),
        st.one_of(st.sampled_from(["a", "b"]), nasty_text),
    ),
    st.dictionaries(st.sampled_from(["type", "seq", "poi", "part", "x"]), anything, max_size=5),
)
injection = st.one_of(
    st.tuples(st.just("ros"), ros_message),
    st.tuples(st.just("udp"), datagram),
)


# ------------------------------------------------------------------ the run


def _dumps(value: Any) -> bytes:
    return json.dumps(value, allow_nan=True, default=str).encode("utf-8", "surrogatepass")[:9000]


async def _tour_with(injections: list[tuple[str, Any]]) -> list[str]:
    """One tour with ``injections`` spread over its first ten simulated minutes; the
    problems found (empty: every property held)."""
    problems: list[str] = []
    async with Running({}, memory=False) as run:  # UDP from a socket of the test's own
        exe, sim = run.executive, run.sim
        world = sim.world
        handle = world.handle

        def watched(topic: str, msg: Any) -> Any:  # the robot's truth when dock arrives
            if topic == "/docking/dock" and isinstance(msg, dict) and msg.get("data") == "dock":
                away = world.pose.distance_to(world.dock_pose.x, world.dock_pose.y)
                if away > 2.0:
                    problems.append(f"dock sent {away:.0f} m from the dock")
            return handle(topic, msg)

        world.handle = watched  # type: ignore[method-assign]
        udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        udp.bind(("127.0.0.1", 0))
        try:
            start = exe.clock.now() if exe.clock.ready else None
            for i, (side, what) in enumerate(injections):
                await after_ticks(exe, lambda: exe.clock.ready)
                start = start if start is not None else exe.clock.now()
                await exe.clock.sleep_until(start + 600.0 * (i + 1) / (len(injections) + 1))
                if run.task is not None and run.task.done():
                    problems.append(f"the executive exited: {run.task.result()}")
                    return problems
                if side == "ros":  # as a rosbridge server's json.dumps writes it (NaN too)
                    role, msg = what
                    frame = {"op": "publish", "topic": TOPICS[role], "msg": msg}
                    text = json.dumps(frame, allow_nan=True, default=str)
                    server = sim._rosbridge
                    for client in list(server._connections):
                        server._enqueue(client, text)
                else:
                    udp.sendto(_dumps(what), run.listen)
            await after_ticks(
                exe,
                lambda: (
                    exe.core.board.get(keys.HELP) is not None
                    or (
                        exe.core.board.get(keys.TOUR_STATE) in (TourState.ENDED, TourState.ABORTED)
                        and world.docking_state == "docked"
                    )
                ),
                120,
            )
            if run.task is not None and run.task.done():
                problems.append("the executive exited")
        finally:
            udp.close()
    return problems


@pytest.mark.timeout(3600 if LONG else 240)
@settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=not LONG,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.data_too_large,
        HealthCheck.function_scoped_fixture,
    ],
    database=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],  # a tour each: no shrinking
)
@given(injections=st.lists(injection, min_size=20, max_size=60))
def test_no_generated_input_stops_the_executive_or_docks_it_away(injections, caplog):
    caplog.clear()
    caplog.set_level(logging.INFO)
    problems = asyncio.run(_tour_with(injections))
    assert problems == []
    for record in caplog.records:
        if record.name.startswith("frog_bt"):
            message = record.getMessage()
            assert "\n" not in message and "\x1b" not in message, message[:200]
