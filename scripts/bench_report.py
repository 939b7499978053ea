#!/usr/bin/env python3
"""What `frog-bt report` costs: its throughput over a corpus beside merely reading every
message of the same files with the mcap library, one job and two, in one run.

    .venv/bin/python scripts/bench_report.py --corpus season/      # made by scripts/corpus
    .venv/bin/python scripts/bench_report.py --tours 40           # makes one first

Each figure is the best of ``--runs`` (the files are in the page cache after the first
read, for every contender alike). Goals (issue 22): report >= 50 % of the plain read's
throughput; --jobs 2 >= 1.6x one job. Also prints the expected time for a year of one
robot (2,400 tours).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from typing import Any

from bench_support import emit
from mcap.reader import make_reader

from frog_bt.config import load_site
from frog_bt.offline.corpus import recordings
from frog_bt.offline.executors import executor
from frog_bt.offline.report.corpus import read_corpus
from frog_bt.offline.report.rows import rows

YEAR = 2400  # tours of one robot in a year


def plain_read(files: list[Path]) -> int:
    """Every message of every file, through the mcap library's reader (no decoding)."""
    n = 0
    for path in files:
        with open(path, "rb") as f:
            for _ in make_reader(f).iter_messages(log_time_order=False):
                n += 1
    return n


def report(files: list[Path], jobs: int) -> int:
    site = load_site()
    with executor(jobs) as pool:
        return len(rows(read_corpus(files, site, pool), site))


def best(fn: Any, runs: int) -> tuple[float, Any]:
    times, result = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--corpus", type=Path, help="a directory of recordings (scripts/corpus)")
    p.add_argument("--tours", type=int, default=40, help="without --corpus: make this many")
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--out", help="write the figures as JSON here")
    a = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="frog-bench-report-") as tmp:
        corpus = a.corpus
        if corpus is None:
            from corpus_run import make

            corpus = Path(tmp)
            make(corpus, days=max(1, a.tours // 20), per_day=min(a.tours, 20), seed=1, jobs=2)
        files = recordings([corpus])
        size = sum(f.stat().st_size for f in files) / 1e6
        plain_s, messages = best(lambda: plain_read(files), a.runs)
        one_s, tours = best(lambda: report(files, 1), a.runs)
        two_s, _ = best(lambda: report(files, 2), a.runs)
    out = {
        "files": len(files),
        "tours": tours,
        "mb": round(size, 1),
        "messages": messages,
        "plain_read_s": round(plain_s, 2),
        "report_1_job_s": round(one_s, 2),
        "report_2_jobs_s": round(two_s, 2),
        "report_vs_plain_read": round(plain_s / one_s, 2),
        "two_jobs_speedup": round(one_s / two_s, 2),
        "year_of_one_robot_s": round(YEAR * two_s / max(tours, 1), 0),
    }
    print(f"{len(files)} files, {tours} tours, {size:.0f} MB, {messages:,} messages")
    print(f"plain read (mcap):  {plain_s:6.2f} s  {size / plain_s:6.1f} MB/s")
    print(
        f"report, 1 job:      {one_s:6.2f} s  {size / one_s:6.1f} MB/s  "
        f"({100 * plain_s / one_s:.0f} % of the plain read)"
    )
    print(
        f"report, 2 jobs:     {two_s:6.2f} s  {size / two_s:6.1f} MB/s  "
        f"({one_s / two_s:.2f}x one job)"
    )
    print(
        f"a year of one robot ({YEAR} tours): about {out['year_of_one_robot_s'] / 60:.1f} "
        "min with 2 jobs"
    )
    emit(out, a.out)


if __name__ == "__main__":
    main()
