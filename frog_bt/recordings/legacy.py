"""Recordings made before the events were recorded as themselves: their event channels read.

In recordings written before then, ``/frog_bt/tick``, ``blame``, ``operator``, ``alert``,
``doubt``, ``fault`` and ``links`` held a shape of their own for each event, without its
time (the message's log time) and without its tag. Their schema names tell them apart
from today's (``frog_bt/Tick`` against ``frog_bt/Ticked``), and their fields are the
event's, so each is read as the event it stands for: the fields taken as they are, the
time from the log, and for an alert or the links' states the whole message as the
event's one value.

=====================  =========================  ==============================
old schema name        event                      the old message is
=====================  =========================  ==============================
``frog_bt/Tick``       :class:`Ticked`            its fields
``frog_bt/Blame``      :class:`Blamed`            its fields
``frog_bt/Operator``   :class:`OperatorDone`      its fields
``frog_bt/Doubt``      :class:`Doubted`           its fields
``frog_bt/Fault``      :class:`Faulted`           its fields
``frog_bt/Alert``      :class:`AlertChanged`      its ``alert``
``frog_bt/Links``      :class:`LinksChanged`      its ``links``
=====================  =========================  ==============================
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from frog_bt.codec import convert, decoder
from frog_bt.model.events import (
    AlertChanged,
    Blamed,
    Doubted,
    Faulted,
    LinksChanged,
    OperatorDone,
    Recorded,
    Ticked,
)

__all__ = ["LEGACY", "legacy_decoder"]

LEGACY: dict[str, tuple[type[Recorded], str | None]] = {
    "frog_bt/Tick": (Ticked, None),
    "frog_bt/Blame": (Blamed, None),
    "frog_bt/Operator": (OperatorDone, None),
    "frog_bt/Doubt": (Doubted, None),
    "frog_bt/Fault": (Faulted, None),
    "frog_bt/Alert": (AlertChanged, "alert"),
    "frog_bt/Links": (LinksChanged, "links"),
}
"""Old schema name -> the event it stands for, and the field the whole message is (None:
the message's fields are the event's)."""

_OBJECT = decoder(dict[str, Any])


def legacy_decoder(schema: str) -> Callable[[float, bytes], Recorded] | None:
    """The decoder of an old event channel by its schema name (None: not an old one); it
    takes the message's log time and bytes, and raises only DecodeError."""
    known = LEGACY.get(schema)
    if known is None:
        return None
    cls, whole = known

    def decode(t: float, data: bytes) -> Recorded:
        obj = _OBJECT(data)
        return convert({**obj, "t": t} if whole is None else {"t": t, whole: obj}, cls)

    return decode
