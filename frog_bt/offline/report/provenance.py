"""Where the figures come from: the recordings' date range, the frog-bt versions that
wrote them (the MCAP header's ``library``), the trees that ran (a hash of
``/frog_bt/tree``), the site configurations (their hash, recorded at start: metadata
``frog_bt_site``), the runs (metadata ``frog_bt_run``: how many, and the files recorded
before run ids, whose copies are found by time alone), the files skipped and why (a copy
of a file of the same run among them), the suspicious overlaps (two runs of one robot at
once: both counted), and those read only in part (cut short: what was recovered)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from datetime import datetime
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.offline.report.facts import FileFacts

NOT_RECORDED = "not recorded"


def provenance(
    facts: list[FileFacts], skipped: list[str], suspicious: Sequence[str] = ()
) -> dict[str, Any]:
    read = [f for f in facts if not f.error]
    first = min((f.start for f in read), default=None)
    last = max((max(f.start, f.end) for f in read), default=None)

    def local(t: float | None) -> str | None:
        return None if t is None else datetime.fromtimestamp(t, SITE_TZ).isoformat("T", "seconds")

    return {
        "files": len(read),
        "first": local(first),
        "last": local(last),
        "versions": dict(Counter(f.library or NOT_RECORDED for f in read).most_common()),
        "trees": dict(Counter(f.tree or NOT_RECORDED for f in read).most_common()),
        "configs": dict(Counter(f.config or NOT_RECORDED for f in read).most_common()),
        "runs": len({f.run for f in read if f.run}),
        "without_run_id": sum(not f.run for f in read),
        "skipped": skipped,
        "suspicious": list(suspicious),
        "cut_short": [f"{f.file}: {f.recovered}" for f in read if f.recovered],
    }
