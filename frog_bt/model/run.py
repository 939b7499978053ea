"""Which run a recording belongs to: a run id, and the robot that made it.

A *run* is what one executive does from the moment it starts afresh: a UUID is drawn
then (:meth:`RunId.new`) and every file it records carries it (MCAP metadata
:data:`RUN_METADATA`, also in each file ``--record DIR`` rotates into). An executive
restarted from a checkpoint carries the run on: the checkpoint keeps the id, and the
resumed executive's files keep it too and name the run they resume (``resumes``). So two
files with one run id are one run's (rotations, a resumption, or a copy of one file), and
files with different ids are different runs, whatever their times
(:mod:`frog_bt.offline.report.runs`).

:func:`read_metadata` takes the metadata back from a file, believing only what fits: a
UUID, a robot name as the site configuration allows it (``alerts.robot``).
"""

from __future__ import annotations

import re
import uuid
from collections.abc import Mapping
from dataclasses import dataclass

RUN_METADATA = "frog_bt_run"  # MCAP metadata in every file: id, robot, resumes
ROBOT_NAME = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")  # as config.AlertsCfg.robot


@dataclass(frozen=True, slots=True)
class RunId:
    id: str  # a UUID, drawn when an executive starts afresh
    resumes: str = ""  # a resumed executive's: the run it carries on (its id is that run's)

    @classmethod
    def new(cls) -> RunId:
        return cls(str(uuid.uuid4()))

    @classmethod
    def resuming(cls, run: str) -> RunId:
        """The run a checkpoint written by run ``run`` carries on."""
        return cls(run, resumes=run)

    def metadata(self, robot: str) -> dict[str, str]:
        """The :data:`RUN_METADATA` record of a file of this run, by ``robot``."""
        out = {"id": self.id, "robot": robot}
        if self.resumes:
            out["resumes"] = self.resumes
        return out


@dataclass(frozen=True, slots=True)
class Recorded:
    """A file's run as read back: empty strings where it says nothing usable (a file
    recorded before run ids, or metadata that does not fit)."""

    id: str = ""
    robot: str = ""
    resumes: str = ""


def valid_id(text: object) -> str:
    """``text`` when it is a UUID (canonical form), else ``""``."""
    if not isinstance(text, str):
        return ""
    try:
        return str(uuid.UUID(text)) if len(text) == 36 else ""
    except ValueError:
        return ""


def read_metadata(metadata: Mapping[str, Mapping[str, str]]) -> Recorded:
    """The run a file's MCAP metadata names (``metadata``: name -> record)."""
    record = metadata.get(RUN_METADATA, {})
    robot = record.get("robot", "")
    return Recorded(
        valid_id(record.get("id")),
        robot if isinstance(robot, str) and ROBOT_NAME.match(robot) else "",
        valid_id(record.get("resumes")),
    )
