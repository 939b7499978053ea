"""Alerts as episodes: each raise with its acknowledgement (and by whom) and resolution.

``/frog_bt/alert`` records every change of an alert (raised, told again unacknowledged,
acknowledged, cleared); an episode runs from a first raise to its clearing. The changes
of one robot are read in time order over all its files, so that an alert raised in one
file and acknowledged or cleared in the next is one episode. Who acknowledged comes from
the ``ack_alert`` operator command that did it (``by``: console, ctl, link).
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

from frog_bt.engine.operator import Command
from frog_bt.offline.report.facts import AlertChange, FileFacts, OperatorCall
from frog_bt.runtime.alerts import KINDS
from frog_bt.runtime.staff import REMEMBER_ACKS

ACK_WINDOW = 2.0  # seconds: an ack_alert command and the acknowledgement it caused
OUTLIVED = REMEMBER_ACKS  # seconds from a run's end in which a raise anew continues an episode


def needs_help(kind: str) -> bool:
    """The robot holds and asks a person (its answers include ``done_by_hand``)."""
    spec = KINDS.get(kind)
    return spec is not None and Command.DONE_BY_HAND.value in spec.answers


class Restart(NamedTuple):
    """An executive started (``started``) after a recording that ended at ``previous_end``."""

    previous_end: float
    started: float


@dataclass
class Episode:
    """One alert, from its raise to its clearing (times in project-clock seconds)."""

    id: str
    kind: str
    severity: str
    subject: str
    raised: float
    acknowledged: float | None = None
    acknowledged_by: str = ""
    cleared: float | None = None
    repeats: int = 0  # told again unacknowledged (escalation)
    last: float = 0.0  # its latest change

    @property
    def help(self) -> bool:
        return needs_help(self.kind)

    @property
    def to_acknowledge(self) -> float | None:
        """Seconds from the raise to the acknowledgement (None: never acknowledged)."""
        return None if self.acknowledged is None else self.acknowledged - self.raised


def runs_of(files: list[FileFacts]) -> list[Restart]:
    """One robot's executive starts, each with the end of the recording before it."""
    ends = sorted(f.end for f in files)
    out = []
    for t in sorted(t for f in files for t in f.restarts):
        before = bisect.bisect_right(ends, t)  # the files ended by then; the last is latest
        out.append(Restart(ends[before - 1] if before else t, t))
    return out


def _run_ended(runs: list[Restart], episode: Episode, t: float) -> bool:
    """Whether a raise anew at ``t`` of an alert still open in ``episode`` is a new
    episode. A new executive knows no alert: one its predecessor left up ended with that
    run, unseen, unless the condition outlived the restart: raised again within
    :data:`OUTLIVED` seconds of the end of the run before."""
    started = [r for r in runs if episode.last < r.started <= t]
    return bool(started) and t - started[-1].previous_end > OUTLIVED


def episodes(
    changes: list[AlertChange], calls: list[OperatorCall], runs: Sequence[Restart] = ()
) -> list[Episode]:
    """The episodes of one robot's alert changes (any order), in order of their raise. A
    change of an alert whose raise is not in the corpus opens an episode there. ``runs``:
    the robot's executive starts (:func:`runs_of`), to tell an alert raised again by a
    later run from the one an earlier run left up."""
    open_: dict[str, Episode] = {}
    out: list[Episode] = []
    starts = sorted(runs, key=lambda r: r.started)
    acks = sorted((c for c in calls if c.command == Command.ACK_ALERT and c.ok), key=lambda c: c.t)
    for change in sorted(changes, key=lambda c: c.t):
        episode = open_.get(change.id)
        if (
            episode is not None
            and change.state == "raised"
            and change.repeat == 0
            and _run_ended(starts, episode, change.t)
        ):
            del open_[change.id]
            episode = None
        if episode is None:
            if change.state == "cleared":
                continue  # cleared, its raise not in the corpus: nothing to count
            episode = Episode(change.id, change.kind, change.severity, change.subject, change.t)
            open_[change.id] = episode
            out.append(episode)
        elif change.state == "raised":
            episode.repeats += change.repeat > 0
        episode.last = change.t
        if change.state == "acknowledged" and episode.acknowledged is None:
            episode.acknowledged = change.t
            episode.acknowledged_by = next(
                (
                    c.by or "operator"
                    for c in reversed(acks)
                    if c.id == change.id and episode.raised <= c.t <= change.t + ACK_WINDOW
                ),
                "",
            )
        elif change.state == "cleared":
            episode.cleared = change.t
            del open_[change.id]
    return out
