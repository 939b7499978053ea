"""Commands read back from a recording, and how two of them differ in domain terms.

Replay (:mod:`frog_bt.offline.replay`) and ``sim --play`` (:mod:`frog_bt.sim.play`)
compare the commands a tree sends with the recorded ones through these.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.config import Site
from frog_bt.errors import FrogError
from frog_bt.model.channels import FRONTEND_OUT
from frog_bt.model.ros import POSE
from frog_bt.recordings.mcapfile import RecordingFile, open_recording


class ReplayError(FrogError):
    """The recording cannot be replayed (not a file, not MCAP, channels missing)."""


@dataclass(slots=True)
class Command:
    """One command sent: when, on which channel (ROS topic or ``/frontend/out``), what,
    and the tree node that sent it (``node``: blame; empty when the recording has none)."""

    t: float
    channel: str
    payload: dict[str, Any]
    node: str = ""
    reads: dict[str, str] = field(default_factory=dict)  # what the node read (blame)

    def __str__(self) -> str:
        return f"{self.channel} {json.dumps(self.payload, sort_keys=True)}"


def chain(path: Path) -> list[RecordingFile]:
    """The recording at ``path``, after its lead-in when it continues one (a tour file of
    ``--record DIR`` continues the idle file before it: the tree was already running)."""
    recording = open_recording(path)
    lead_in = recording.metadata.get("frog_bt", {}).get("lead_in")
    if not lead_in:
        return [recording]
    before = Path(path).parent / lead_in
    if not before.is_file():
        raise ReplayError(
            f"{path}: continues {lead_in}, which is gone (deleted by the "
            "recording budget?); it cannot be replayed without it"
        )
    return [open_recording(before), recording]


def local_time(t: float) -> str:
    """``2026-06-01 10:42:13.2`` at the site."""
    return datetime.fromtimestamp(t, SITE_TZ).strftime("%Y-%m-%d %H:%M:%S.%f")[:-5]


def plain(value: Any) -> Any:
    """JSON round trip: the values a recording gives back (lists, not tuples)."""
    return json.loads(json.dumps(value))


def without_stamp(msg: Any) -> Any:
    """A ROS message without its header's stamp (the time it was sent, which differs
    between two runs of the same commands; the rest is what is compared)."""
    header = msg.get("header") if isinstance(msg, dict) else None
    if isinstance(header, dict) and "stamp" in header:
        msg = {**msg, "header": {k: v for k, v in header.items() if k != "stamp"}}
    return msg


# ------------------------------------------------------------------ the report, in domain terms


def _fields(command: Command, site: Site) -> tuple[str, dict[str, Any]]:
    """What a command is (``/GotoWayPoint``, ``start_poi``) and its fields in domain
    terms: a goal's waypoint by name, a front-end message's fields."""
    if command.channel == site.topic("goto"):
        return command.channel, {"waypoint": site.waypoint_of(POSE.convert(command.payload))}
    if command.channel == FRONTEND_OUT:
        fields = dict(command.payload)
        return str(fields.pop("type", "?")), fields
    payload = command.payload
    return command.channel, dict(payload) if isinstance(payload, dict) else {"msg": payload}


def describe(command: Command | None, site: Site) -> str:
    """``/GotoWayPoint waypoint POI1a``, ``start_poi poi POI2 part b``; ``nothing``."""
    if command is None:
        return "nothing"
    what, fields = _fields(command, site)
    return " ".join([what, *(f"{k} {_short_value(v)}" for k, v in fields.items())])


def differences(expected: Command | None, got: Command | None, site: Site) -> str:
    """The difference in domain terms: ``waypoint POI1a → POI1b``, or ``start_poi part b
    → finish_poi`` when the commands are of different kinds."""
    if expected is None or got is None:
        return f"{describe(expected, site)} → {describe(got, site)}"
    (a, fa), (b, fb) = _fields(expected, site), _fields(got, site)
    if a != b:
        return f"{describe(expected, site)} → {describe(got, site)}"
    changed = [
        f"{k} {_short_value(fa.get(k))} → {_short_value(fb.get(k))}"
        for k in sorted(set(fa) | set(fb))
        if fa.get(k) != fb.get(k)
    ]
    return "; ".join(changed) or "the same fields (at another time)"


def what_differs(expected: Command | None, got: Command | None, site: Site) -> str:
    """What a divergence is about, for grouping: the first field that differs
    (``waypoint``), or the two kinds (``start_poi → finish_poi``, ``/GotoWayPoint →
    nothing``)."""
    if expected is None or got is None:
        a = _fields(expected, site)[0] if expected else "nothing"
        b = _fields(got, site)[0] if got else "nothing"
        return f"{a} → {b}"
    (a, fa), (b, fb) = _fields(expected, site), _fields(got, site)
    if a != b:
        return f"{a} → {b}"
    changed = sorted(k for k in set(fa) | set(fb) if fa.get(k) != fb.get(k))
    return changed[0] if changed else "time"


def _short_value(value: Any) -> str:
    if isinstance(value, float):
        value = round(value, 3)
    text = value if isinstance(value, str) else json.dumps(value, sort_keys=True)
    return text if len(text) <= 60 else text[:57] + "..."
