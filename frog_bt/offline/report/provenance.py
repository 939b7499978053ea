"""Where the figures come from: the recordings' date range, the frog-bt versions that
wrote them (the MCAP header's ``library``), the trees that ran (a hash of
``/frog_bt/tree``), the site configurations (their hash, recorded at start: metadata
``frog_bt_site``), the files skipped and why, and those read only in part (cut short:
what was recovered)."""

from __future__ import annotations

from collections import Counter
from datetime import datetime
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.offline.report.facts import FileFacts

NOT_RECORDED = "not recorded"


def provenance(facts: list[FileFacts], skipped: list[str]) -> dict[str, Any]:
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
        "skipped": skipped,
        "cut_short": [f"{f.file}: {f.recovered}" for f in read if f.recovered],
    }
