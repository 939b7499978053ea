"""The blackboard keys and their types: one declaration per key.

Inputs get their types from the wire table (a :class:`~frog_bt.kernel.blackboard.Reading`
of the ROS value, or for samples and queues a tuple); the keys tree nodes write
are listed in :data:`WRITTEN`. A node type may state the type it reads or writes
a key as (``key_types``); the check before anything connects refuses a node whose
type disagrees with the key's, and a key no declaration knows.
"""

from __future__ import annotations

from typing import Any

from frog_bt.kernel.blackboard import EventLog, Reading
from frog_bt.maths.engagement import Decision, Samples
from frog_bt.wire import INPUTS, Keep

# keys tree nodes write -> the type of their value (None allowed where it says so)
WRITTEN: dict[str, Any] = {
    "/visitor": int,  # the tracked id of the visitor being guided
    "/approach_failed": dict,  # visitor id -> project time an approach failed
    "/declined": frozenset,  # visitor ids who said no
    "/frontend_ready": bool,
    "/tour_state": str,  # started, ended, aborted
    "/special_done": frozenset,  # special-content spots played this tour
    "/target": str,  # the logical POI driven to
    "/waypoint": str,  # its time-of-day variant
    "/skipped": str | None,  # the stop skipped, if any
    "/abort_reason": str | None,
    "/abort_reason_last": str | None,
    "/icl": bool,  # the face stream is on
    "/engagement": Samples,
    "/engagement_meter": float | None,
    "/engaged": bool | None,  # None: no data
    "/engagement_decision": tuple[str, Decision],  # (about, decision)
}

FIXED: dict[str, Any] = {"/now": float, "/events": EventLog, "/frontend_ready": bool,
                         "/link": Any}


def key_types() -> dict[str, Any]:
    """Every key's type: the fixed inputs, the wire table's inputs and :data:`WRITTEN`."""
    inputs = {inp.key: Reading if inp.keep is Keep.LATEST else tuple
              for inp in INPUTS.values()}
    return {**FIXED, **inputs, **WRITTEN}


def type_name(t: Any) -> str:
    return getattr(t, "__name__", None) or str(t).replace("typing.", "")
