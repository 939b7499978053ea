"""An alert change, as the alert book tells it (:mod:`frog_bt.runtime.alerts`): the value of
:class:`~frog_bt.model.events.AlertChanged`, and of the alert book a rotated file carries."""

from __future__ import annotations

from typing import Literal

import msgspec

__all__ = ["Alert"]


class Alert(msgspec.Struct, frozen=True):
    """One alert change (``state``: raised, cleared = resolved, acknowledged by a person).

    The fields after ``since`` came later, each with a default, so older recordings still
    decode: ``severity`` in ROS diagnostics' levels (REP-107), ``key`` the stable
    deduplication key (``frog-bt:<robot>:<kind>[:<subject>]``), ``subject`` what it is
    about (a stop), ``answers`` the operator commands that apply, ``what`` and ``todo``
    the two halves of ``text`` (the sentence, what to do), ``repeat`` how many times it
    has been told again unacknowledged (escalation; 0: the first telling) and ``waited``
    the project-clock seconds since it was raised, at that repeat."""

    id: str
    kind: str
    text: str
    state: Literal["raised", "cleared", "acknowledged"]
    since: float
    severity: Literal["WARN", "ERROR"] = "WARN"
    key: str = ""
    subject: str = ""
    answers: tuple[str, ...] = ()
    what: str = ""
    todo: str = ""
    repeat: int = 0
    waited: float = 0.0

    @property
    def occurrence(self) -> str:
        """Which raise of this alert: its raise time as text (the same through escalation,
        clearing and acknowledgement; a later raise of the same alert has another)."""
        return f"{self.since:.6f}"
