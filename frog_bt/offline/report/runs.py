"""Which files are one run: the lanes tours are joined in, copies, suspicious overlaps.

Every recording names its run (metadata ``frog_bt_run``, :mod:`frog_bt.model.run`): the
files one executive wrote, those ``--record DIR`` rotated into and those of an executive
that resumed the run from its checkpoint all carry its id.

* **Lanes**: pieces are joined into tours within one run (:func:`lanes`), so that runs
  whose times overlap (three demos at the simulator's 10:30, a season simulated in
  parallel, two robots' files in one folder) are never taken for one.
* **Copies**: two files of one run cannot overlap in time (more than a rotation's seam,
  :data:`OVERLAP_S`): they are one file twice, whole or cut, put beside each other; the
  one covering more time is read, the other skipped, saying so (:func:`copies`).
* **Suspicious**: two runs of one robot (its configured name) that overlap in time would
  be two executives driving it at once; both are counted, and the provenance says so
  (:func:`suspicious`).

Files recorded before run ids keep the rule of their time: one directory is one robot's
``--record DIR``, its files joined together, and two of them that overlap in time taken
for a copy, saying so.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from frog_bt.offline.report.facts import FileFacts

OVERLAP_S = 1.0  # seconds two files of one run may share (a rotation's seam)


def lane_of(f: FileFacts) -> str:
    """The files whose pieces join: one run's, or one directory's (no run id)."""
    return f"run {f.run}" if f.run else str(Path(f.file).parent)


def lanes(files: list[FileFacts]) -> dict[str, list[FileFacts]]:
    """The files of each lane (:func:`lane_of`), in the order given."""
    out: dict[str, list[FileFacts]] = {}
    for f in files:
        out.setdefault(lane_of(f), []).append(f)
    return out


def copies(files: list[FileFacts]) -> dict[str, str]:
    """Files that overlap another of their lane in time: file -> why it is skipped. Of
    two, the one covering more time is read."""
    out: dict[str, str] = {}
    for group in lanes(files).values():
        for shorter, longer in _overlaps(group):
            name = Path(longer.file).name
            out[shorter.file] = (
                f"the same run as {name} (run {longer.run[:8]}) and overlaps it in time: "
                "a copy (the longer one is read)"
                if longer.run
                else f"overlaps {name} in time, which one robot's recordings cannot: a copy? "
                "(no run id, recorded before run ids: the longer one is read)"
            )
    return out


def _overlaps(group: list[FileFacts]) -> Iterator[tuple[FileFacts, FileFacts]]:
    """(shorter, longer) for each file overlapping the one kept before it, by start (of
    two as long, the first by start and name is kept)."""
    kept: FileFacts | None = None
    for f in sorted(group, key=lambda f: (f.start, f.file)):
        if kept is None or f.start >= kept.end - OVERLAP_S:
            kept = f if kept is None or f.end > kept.end else kept
            continue
        longer = f if f.end - f.start > kept.end - kept.start else kept
        yield (kept if longer is f else f), longer
        kept = longer


def suspicious(files: list[FileFacts]) -> list[str]:
    """Runs of one robot (by its configured name) that overlap in time: one line per file
    that starts while another run's file of its robot is under way (both are counted)."""
    out = []
    robots: dict[str, list[FileFacts]] = {}
    for f in files:
        if f.run and f.robot_name:
            robots.setdefault(f.robot_name, []).append(f)
    for robot, group in sorted(robots.items()):
        latest: dict[str, FileFacts] = {}  # run -> its file ending last, of those started
        for f in sorted(group, key=lambda f: (f.start, f.file)):
            under_way = [g for run, g in latest.items() if run != f.run and g.end > f.start]
            if under_way:
                other = max(under_way, key=lambda g: (g.end, g.file))
                if other.end - f.start > OVERLAP_S:
                    out.append(
                        f"{f.file}: overlaps {Path(other.file).name} in time, a file of another "
                        f"run of robot {robot}: two executives of one robot at once? "
                        "(both are counted)"
                    )
            latest = {run: g for run, g in latest.items() if g.end > f.start}
            if f.run not in latest or f.end > latest[f.run].end:
                latest[f.run] = f
    return out
