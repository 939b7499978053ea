"""A screenshot of the real rerun viewer on a telemetry file, at a chosen tick.

The viewer opens a recording at its end (the time panel follows the newest data), so
the recording is first cut after ``--tick`` (static data and the default layout kept),
then ``rerun --screenshot-to`` renders it and quits. Without a screen, under Xvfb and
Mesa's software Vulkan (docs/TELEMETRY.md, "Screenshots without a screen")::

    Xvfb :99 -screen 0 1600x1000x24 &
    DISPLAY=:99 .venv/bin/python scripts/viewer_screenshot.py tour.rrd --tick 4400 \\
        --out docs/viewer-help.png

``--tick`` defaults to the tick of the first staff bookmark (an alert raised, a
command), or with ``--skipped``, of the first stop whose lane says skipped, plus 10.
(``rerun rrd split`` would cut too, but leaves the static data out: no map transform.)
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import pyarrow.compute as pc


def first_tick(path: Path, skipped: bool) -> int:
    """The tick of the first staff bookmark, or of the first stop skipped."""
    from rerun.chunk import RrdReader

    found: list[int] = []
    for chunk in RrdReader(path).stream():
        entity = str(chunk.entity_path)
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        if skipped and entity.startswith("/stops/") and "StateChange:state" in batch.schema.names:
            states = batch.column("StateChange:state").to_pylist()
            ticks = batch.column("tick").to_pylist()
            found += [t for t, s in zip(ticks, states, strict=True) if s == ["skipped"]]
        elif not skipped and entity == "/log/bookmarks/staff":
            found += batch.column("tick").to_pylist()
    if not found:
        sys.exit(f"{path}: no {'skipped stop' if skipped else 'staff bookmark'} in it")
    return min(found)


def cut(path: Path, tick: int, out: Path) -> None:
    """``path`` up to ``tick`` (inclusive) in ``out``: static data, rows of ticks <= tick,
    and the default layout, made again for the packaged tree and site (the SDK cannot
    write a blueprint store read back from a file)."""
    import rerun as rr
    from rerun.chunk import Chunk, RrdReader

    from frog_bt.behaviours import load_tree
    from frog_bt.config import load_site
    from frog_bt.live.telemetry.blueprint import default_blueprint
    from frog_bt.live.telemetry.layout import TreeIndex

    reader = RrdReader(path)
    [entry] = reader.recordings()
    rec = rr.RecordingStream(entry.application_id, recording_id=f"{entry.recording_id}-cut")
    rec.save(str(out))
    kept: list[Any] = []
    for chunk in reader.stream():
        if chunk.is_static or "tick" not in chunk.timeline_names:
            kept.append(chunk)
            continue
        batch = chunk.to_record_batch()
        rows = batch.filter(pc.less_equal(batch.column("tick"), tick))
        if rows.num_rows:
            made = Chunk.from_record_batch(rows)
            kept.extend(made if isinstance(made, list) else [made])
    site = load_site()
    index = TreeIndex.of(load_tree(site=site).root)
    stops = [stop.poi for stop in site.tour.stops]
    rec.send_blueprint(default_blueprint(index, "bt", stops), make_active=True, make_default=True)
    rec.send_chunks(kept)
    rec.flush()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("rrd", type=Path)
    p.add_argument("--tick", type=int, help="the last tick shown (default: see above)")
    p.add_argument("--skipped", action="store_true", help="default tick: a stop skipped")
    p.add_argument("--out", type=Path, required=True, help="the PNG to write")
    p.add_argument("--size", default="1600x1000", help="window size (default 1600x1000)")
    p.add_argument("--port", type=int, default=9899, help="the viewer's port (not 9876)")
    args = p.parse_args()
    if not os.environ.get("DISPLAY"):
        sys.exit("no DISPLAY: start Xvfb (see --help)")
    tick = args.tick if args.tick is not None else first_tick(args.rrd, args.skipped) + 10
    viewer = Path(sys.executable).parent / "rerun"
    with tempfile.TemporaryDirectory(prefix="frog-shot-") as tmp:
        cut_file = Path(tmp) / "cut.rrd"
        cut(args.rrd, tick, cut_file)
        subprocess.run(
            [
                str(viewer),
                "--port",
                str(args.port),
                "--window-size",
                args.size,
                "--screenshot-to",
                str(args.out),
                str(cut_file),
            ],
            env={**os.environ, "RUST_LOG": "error"},
            check=True,
            timeout=600,
        )
    print(f"{args.out}: {args.rrd} up to tick {tick}")


if __name__ == "__main__":
    main()
