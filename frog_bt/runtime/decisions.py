"""What staff decided, kept across a restart: a small file beside the checkpoint.

Out of service, a pause, the help the robot waits for and the alerts a person has
acknowledged must outlive the process (systemd's ``Restart=always`` brings a new one up
at once): :func:`save` writes them atomically whenever they change, :func:`load` gives
them back at start-up. ``--fresh`` (and ``--checkpoint none``) start without them.

What an executive took up at start-up (these and its checkpoint's resume point) is
recorded once (:func:`restored`, on ``/frog_bt/restored``), so that replay starts from
the same (:func:`taken_up`).
"""

from __future__ import annotations

import contextlib
import json
from dataclasses import dataclass, field
from pathlib import Path

from frog_bt.model.channels import Restored, RestoredHelp
from frog_bt.model.help import Help, HelpAbout
from frog_bt.model.progress import Resume
from frog_bt.runtime.checkpoint import write_json
from frog_bt.text import LINE, inert

__all__ = ["Decisions", "load", "path_for", "restored", "save", "taken_up"]

VERSION = 1


@dataclass(frozen=True, slots=True)
class Decisions:
    in_service: bool = True
    paused: bool = False
    help: Help | None = None
    acknowledged: frozenset[str] = field(default_factory=frozenset)

    def to_json(self) -> dict[str, object]:
        return {
            "version": VERSION,
            "in_service": self.in_service,
            "paused": self.paused,
            "help": (
                {
                    "about": self.help.about.value,
                    "since": self.help.since,
                    "detail": self.help.detail,
                }
                if self.help is not None
                else None
            ),
            "acknowledged": sorted(self.acknowledged),
        }


NONE = Decisions()


def path_for(checkpoint: Path) -> Path:
    """The decisions file of the executive whose checkpoint is ``checkpoint``."""
    return checkpoint.with_name(checkpoint.name + ".staff")


def save(path: Path, decisions: Decisions) -> None:
    """Write ``decisions`` atomically; none at all removes the file."""
    write_json(path, decisions.to_json() if decisions != NONE else None)


def load(path: Path) -> Decisions:
    """The decisions in ``path``; none when there is no file or it cannot be read."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return NONE
    if not isinstance(data, dict) or data.get("version") != VERSION:
        return NONE
    help_ = None
    raw = data.get("help")
    if isinstance(raw, dict):
        with contextlib.suppress(ValueError, TypeError):
            detail = raw.get("detail", "")
            help_ = Help(
                HelpAbout(raw.get("about", "")),
                float(raw.get("since", 0.0)),
                inert(detail, LINE) if isinstance(detail, str) else "",
            )
    acked = data.get("acknowledged")
    return Decisions(
        in_service=data.get("in_service") is not False,
        paused=data.get("paused") is True,
        help=help_,
        acknowledged=frozenset(a for a in acked if isinstance(a, str))
        if isinstance(acked, list)
        else frozenset(),
    )


def restored(resume: Resume | None, decided: Decisions) -> Restored | None:
    """What a starting executive takes up from before it, as recorded; None for nothing."""
    if resume is None and decided == NONE:
        return None
    return Restored(
        done=list(resume.order) if resume is not None else [],
        visitor=resume.visitor if resume is not None else None,
        written=resume.written if resume is not None else 0.0,
        in_service=decided.in_service,
        paused=decided.paused,
        help=(
            RestoredHelp(decided.help.about.value, decided.help.since, decided.help.detail)
            if decided.help is not None
            else None
        ),
        acknowledged=sorted(decided.acknowledged),
    )


def taken_up(recorded: Restored) -> tuple[Resume | None, Decisions]:
    """The resume point and the decisions a recorded :class:`Restored` says the executive
    started from (a help of an unknown kind is left out, as :func:`load` does)."""
    resume = (
        Resume(frozenset(recorded.done), recorded.visitor, tuple(recorded.done), recorded.written)
        if recorded.done
        else None
    )
    help_ = None
    if recorded.help is not None:
        with contextlib.suppress(ValueError):
            help_ = Help(
                HelpAbout(recorded.help.about),
                recorded.help.since,
                inert(recorded.help.detail, LINE),
            )
    return resume, Decisions(
        in_service=recorded.in_service,
        paused=recorded.paused,
        help=help_,
        acknowledged=frozenset(recorded.acknowledged),
    )
