"""rerun SDK memory, alone: RSS while a recording stream saves rows to a file.

No frog-bt code: one ``rr.RecordingStream`` saving to an ``.rrd``, ``send_columns``
of 50 rows at a time on the two timelines telemetry uses (tick and time), for
TextLog, Points2D, or 20 scalar lanes. It prints RSS every 10,000 rows, with one
stream for the whole run or a new stream every 10,000 rows (``--rotate``): the
figures in docs/PERFORMANCE.md ("Memory with telemetry").

    .venv/bin/python scripts/bench_rerun_memory.py text [--rotate]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import rerun as rr

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import emit, memory_kb


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("kind", choices=("text", "points", "lanes"))
    p.add_argument("--rotate", action="store_true", help="a new stream every 10,000 rows")
    p.add_argument("--blocks", type=int, default=10, help="blocks of 10,000 rows")
    p.add_argument("--out")
    args = p.parse_args()
    rss: list[int] = []
    with tempfile.TemporaryDirectory(prefix="frog-rrmem-") as tmp:
        rec = rr.RecordingStream("frog-bt-bench")
        rec.save(str(Path(tmp) / "0.rrd"))
        k = 0
        for block in range(args.blocks):
            for _ in range(200):
                t = np.arange(50) + k
                k += 50
                times = [
                    rr.TimeColumn("tick", sequence=t),
                    rr.TimeColumn("time", timestamp=(t * 100_000_000).astype("datetime64[ns]")),
                ]
                if args.kind == "text":
                    rec.send_columns(
                        "log/a",
                        indexes=times,
                        columns=rr.TextLog.columns(text=[f"row {i} of the log" for i in t]),
                    )
                elif args.kind == "points":
                    rec.send_columns(
                        "map/robot",
                        indexes=times,
                        columns=rr.Points2D.columns(positions=np.random.rand(50, 2)),
                    )
                else:
                    for lane in range(20):
                        rec.send_columns(
                            f"bt/{lane}",
                            indexes=times,
                            columns=rr.Scalars.columns(scalars=np.random.rand(50)),
                        )
            rec.flush()
            rss.append(memory_kb().get("rss_kb", 0))
            if args.rotate:
                rec.disconnect()
                rec = rr.RecordingStream("frog-bt-bench")
                rec.save(str(Path(tmp) / f"{block + 1}.rrd"))
        rec.disconnect()
    emit(
        {
            "kind": args.kind,
            "rotate": args.rotate,
            "rows_per_block": 10_000,
            "rss_kb": rss,
            "growth_kb_per_block": (rss[-1] - rss[0]) / max(len(rss) - 1, 1),
        },
        args.out,
    )


if __name__ == "__main__":
    main()
