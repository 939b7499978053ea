"""Batch what-if: replay a corpus of recordings with one tree and configuration.

:func:`replay_corpus` runs :func:`replay_file` over every recording through any
:class:`concurrent.futures.Executor` (``frog-bt replay --jobs N`` uses a process
pool; a distributed executor with the same interface, such as dask.distributed's
``Client.get_executor()``, plugs in the same way). Each recording gives one
:class:`TourRow`: identical, diverged (with its first divergence in domain terms
and the nodes on both sides) or unreadable (with the reason: a truncated or
corrupt file never stops the batch). :func:`summary` groups the divergences by
signature, the replayed node and what differs.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from frog_bt.config import Site


@dataclass(frozen=True, slots=True)
class TourRow:
    file: str
    status: str  # identical | diverged | unreadable
    reason: str = ""  # unreadable: why
    at: float | None = None  # diverged: seconds into the recording
    number: int | None = None  # which command (from 1)
    differs: str = ""  # in domain terms
    recorded_node: str = ""
    replayed_node: str = ""
    signature: str = ""  # node + what differs, for grouping
    recovered: str = ""  # a file cut short: what was read of it
    bad: int = 0  # messages of our own channels that did not decode (reported, skipped)
    bad_first: str = ""  # the first one's reason

    def line(self) -> str:
        note = f" [{self.recovered}]" if self.recovered else ""
        if self.bad:
            note += f" [{self.bad} bad message(s): {self.bad_first}]"
        return self._line() + note

    def _line(self) -> str:
        if self.status == "identical":
            return f"{self.file}: identical"
        if self.status == "unreadable":
            return f"{self.file}: unreadable: {self.reason}"
        return (
            f"{self.file}: diverged at +{self.at:.1f} s, command {self.number}: "
            f"{self.differs} (recorded: {self.recorded_node or '?'}; replayed: "
            f"{self.replayed_node or '?'})"
        )

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def recordings(paths: Iterable[Path]) -> list[Path]:
    """Files as given, and every ``*.mcap`` below each directory, in order."""
    out: list[Path] = []
    for path in paths:
        out += sorted(path.rglob("*.mcap")) if path.is_dir() else [path]
    return out


def replay_file(path: str, tree: str | None, site: Site) -> TourRow:
    """Replay one recording (in a worker process) with a fresh tree (a tree keeps its
    nodes' state, so each replay builds its own); any failure is an unreadable row. The
    site comes with the task: a worker keeps nothing between tasks."""
    from frog_bt.behaviours import load_tree
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import differences, what_differs

    try:
        loaded = load_tree(tree, site)
        result = Replay(Path(path), site, loaded).run()
        recovered = "; ".join(result.recovered)
    except Exception as exc:
        reason = f"{type(exc).__name__}: {exc}".splitlines()[0][:200]
        return TourRow(path, "unreadable", reason=reason)
    div = result.divergence
    bad, bad_first = result.bad_count, result.bad[0] if result.bad else ""
    if div is None:
        return TourRow(path, "identical", recovered=recovered, bad=bad, bad_first=bad_first)
    diff = div.story or differences(div.expected, div.got, site)  # an alert: its story
    recorded = div.expected.node if div.expected else ""
    replayed = div.got.node if div.got else ""
    node = (replayed or recorded or "?").split(" (")[0]
    return TourRow(
        path,
        "diverged",
        at=div.t - result.start,
        number=div.number,
        differs=diff,
        recorded_node=recorded,
        replayed_node=replayed,
        signature=f"{node}: {what_differs(div.expected, div.got, site)}",
        recovered=recovered,
        bad=bad,
        bad_first=bad_first,
    )


def replay_corpus(
    files: list[Path],
    tree: Path | None,
    site: Site,
    executor: Executor,
    progress: Callable[[int, int], None] | None = None,
) -> Iterator[TourRow]:
    """One row per recording, in order, replayed through ``executor``."""
    futures = [
        executor.submit(replay_file, str(f), str(tree) if tree else None, site) for f in files
    ]
    for done, future in enumerate(futures, 1):
        row = future.result()
        if progress is not None:
            progress(done, len(files))
        yield row


def summary(rows: list[TourRow]) -> dict[str, Any]:
    diverged = [r for r in rows if r.status == "diverged"]
    groups = Counter(r.signature for r in diverged)
    return {
        "tours": len(rows),
        "identical": sum(r.status == "identical" for r in rows),
        "diverged": len(diverged),
        "unreadable": sum(r.status == "unreadable" for r in rows),
        "recovered": sum(bool(r.recovered) for r in rows),
        "by_signature": dict(groups.most_common()),
    }


def summary_line(s: dict[str, Any]) -> str:
    parts = [f"{s['diverged']} of {s['tours']} tours diverge"]
    if s["by_signature"]:
        parts[0] += ": " + ", ".join(f"{n} at {sig}" for sig, n in s["by_signature"].items())
    if s["unreadable"]:
        parts.append(f"{s['unreadable']} unreadable")
    if s.get("recovered"):
        parts.append(f"{s['recovered']} recovered from a cut")
    return "; ".join(parts)
