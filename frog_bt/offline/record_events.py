"""TEMPORARY (issue 39): today's reader records as the executive's own events.

The recording reader (:mod:`frog_bt.recordings.reader`) still yields its ``Record``
twins of the events; the one count of tours (:mod:`frog_bt.model.ledger`) takes the
events of :mod:`frog_bt.model.events`. :func:`as_event` bridges the two until the reader
yields those events itself: then this module and its one caller's use of it
(:func:`frog_bt.offline.report.facts.read_file`) go, and the reader's events are fed to
the ledger as they come. Nothing else may import it.
"""

from __future__ import annotations

from frog_bt.model import channels
from frog_bt.model import events as ev
from frog_bt.recordings import reader as rd

__all__ = ["as_event"]


def as_event(record: rd.Record) -> ev.Event | None:
    """The event a record is the twin of (None: a record with no event twin, such as an
    ack, a primer or a message that did not decode). A goal's event carries no
    :class:`~frog_bt.model.goals.Goal` here: the ledger names its pose through the site."""
    match record:
        case rd.RobotInput(t=t, topic=topic, value=value):
            return ev.RobotInput(t, topic, value)
        case rd.RobotCommand(t=t, topic=topic, role=role, value=value, msg=msg):
            return ev.RobotCommand(t, role, topic, value, msg)
        case rd.FrontendIn(t=t, message=message):
            return ev.FrontendIn(t, message)
        case rd.FrontendOut(t=t, message=message):
            return ev.FrontendOut(t, message)
        case rd.Own(t=t, message=channels.Operator() as m):
            return ev.OperatorDone(t, m.tick, m.command, m.ok, m.text, m.id, m.by)
        case rd.Own(t=t, message=channels.Alert() as m):
            return ev.AlertChanged(t, m)
        case rd.Own(t=t, message=channels.Doubt() as m):
            return ev.Doubted(t, m.code, m.goal, m.why, m.answers)
        case rd.Own(t=t, message=channels.Tick() as m):
            return ev.Ticked(t, m.tick, m.status)
    return None
