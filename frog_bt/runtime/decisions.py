"""What staff decided, kept across a restart: a small file beside the checkpoint.

Out of service, a pause, the help the robot waits for and the alerts a person has
acknowledged must outlive the process (systemd's ``Restart=always`` brings a new one up
at once): :func:`save` writes them atomically whenever they change, :func:`load` gives
them back at start-up. ``--fresh`` (and ``--checkpoint none``) start without them.
"""

from __future__ import annotations

import contextlib
import json
from dataclasses import dataclass, field
from pathlib import Path

from frog_bt.model.help import Help, HelpAbout
from frog_bt.runtime.checkpoint import write_json
from frog_bt.text import LINE, inert

__all__ = ["Decisions", "load", "path_for", "save"]

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
