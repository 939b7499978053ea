"""The commands a live executive sends held against a recording's (``frog-bt sim
--play``), sans-I/O: commands in, counts and the first difference out, in replay's domain
terms (:func:`frog_bt.offline.replay.differences`: ``waypoint POI1a → POI1b``).

Commands are compared in order within their stream, not across streams (the order of a
ROS command and a datagram sent in the same tick carries no meaning):

* ``ros``: the ROS outputs (``/GotoWayPoint``, ``/docking/dock``, ...), stamps left out;
* ``frontend``: the front end's commands but the engagement meter (a resend is the
  caller's to drop: the same seq is one command);
* ``meter``: the engagement meter, told apart. One reading goes per 2 s window of face
  data, and where the windows fall moves with the executive's tick timing, so a live
  executive's meter cannot match a recording's reading for reading: readings off by more
  than :data:`METER_TOLERANCE` (or one too many) are counted on their own line, never
  as differences. The decisions the meter feeds (part b or not) are in ``frontend``.

Two commands recorded within :data:`REORDER_WINDOW` of each other may arrive swapped
(a location-awareness volume and an arrival's follow_me off, say: whether they fall in
one tick or two moves with the executive's timing): that is no difference.

A command received when the recording has no more of its stream is counted as past the
recorded ones (an executive that goes on after the recording's end is not wrong for it).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from frog_bt.config import Site
from frog_bt.model.channels import FRONTEND_OUT
from frog_bt.recordings.commands import Command, differences

METER_TOLERANCE = 0.1  # engagement meter levels this close are the same reading
REORDER_WINDOW = 1.0  # recorded seconds within which two commands may come swapped


@dataclass
class Comparison:
    """The commands received against ``recorded``, per stream, in order.

    :meth:`got` takes each command received; :meth:`next_pass` starts over (``--loop``);
    :meth:`line` is the summary. ``start`` is the recording's start, for the ``+12.3 s``
    of the first difference."""

    site: Site
    recorded: list[Command]
    start: float = 0.0
    received: int = 0  # commands but the engagement meter's
    differ: int = 0
    meter: int = 0  # engagement meter readings received
    meter_differ: int = 0  # ... off by more than METER_TOLERANCE (or one too many)
    first: str = ""  # the first difference, in domain terms
    missed: int = 0  # recorded commands of earlier passes (--loop) never received
    beyond: int = 0  # received when the recording had no more of their stream
    _expected: dict[str, deque[Command]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.next_pass(0.0)

    def next_pass(self, offset: float) -> None:
        """Expect the recorded commands (again, ``offset`` seconds later: ``--loop``); what
        the last pass still expected counts as missed."""
        self.missed += self.missing
        self._expected = {}
        for command in self.recorded:
            later = Command(command.t + offset, command.channel, command.payload)
            self._expected.setdefault(stream(command), deque()).append(later)

    def got(self, command: Command) -> str | None:
        """Take one command received; returns the difference in domain terms when it
        differs from the next recorded one of its stream, else None."""
        kind = stream(command)
        queue = self._expected.get(kind)
        expected = queue.popleft() if queue else None
        if kind == "meter":
            self.meter += 1
            self.meter_differ += not (expected is not None and same(expected, command))
            return None
        self.received += 1
        if expected is None:
            self.beyond += 1  # the recording has no more of these: nothing to hold it to
            return None
        if same(expected, command):
            return None
        assert queue is not None
        swapped = next(
            (
                i
                for i, later in enumerate(queue)
                if later.t - expected.t <= REORDER_WINDOW and same(later, command)
            ),
            None,
        )
        if swapped is not None:  # the same command, a moment earlier than recorded: the
            del queue[swapped]  # one it passed is still to come
            queue.appendleft(expected)
            return None
        self.differ += 1
        text = differences(expected, command, self.site)
        if not self.first:
            self.first = f"at +{command.t - self.start:.1f} s: {text}"
        return text

    @property
    def missing(self) -> int:
        """Recorded commands (but meter readings) not received (yet) in this pass."""
        return sum(len(q) for kind, q in self._expected.items() if kind != "meter")

    def line(self) -> str:
        """``commands: 85 received, 0 differ from the recording[, ...]``."""
        text = f"commands: {self.received} received, {self.differ} differ from the recording"
        if self.missing + self.missed:
            text += f", {self.missing + self.missed} recorded not received"
        if self.beyond:
            text += f", {self.beyond} past the recorded ones"
        if self.first:
            text += f"; first difference {self.first}"
        if self.meter:
            text += (
                f"; engagement meter: {self.meter} readings, {self.meter_differ} off by "
                f"more than {METER_TOLERANCE:g} (its windows move with tick timing)"
            )
        return text


def stream(command: Command) -> str:
    """The stream a command is compared in: ``ros``, ``frontend`` or ``meter``."""
    if command.channel != FRONTEND_OUT:
        return "ros"
    return "meter" if command.payload.get("type") == "engagement" else "frontend"


def same(expected: Command, got: Command) -> bool:
    """Whether ``got`` is ``expected`` (a meter reading: within :data:`METER_TOLERANCE`);
    their times do not count."""
    if (expected.channel, expected.payload) == (got.channel, got.payload):
        return True
    if stream(expected) == stream(got) == "meter":
        a, b = expected.payload.get("level"), got.payload.get("level")
        return (
            isinstance(a, int | float)
            and isinstance(b, int | float)
            and abs(a - b) <= METER_TOLERANCE
        )
    return False
