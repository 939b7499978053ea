"""What the recorded tours tell: one row per tour, totals and rates, plots.

Reads MCAP recordings (files, or directories of *.mcap, as `frog-bt run --record DIR`
writes them) without re-running the tree, joins the pieces of a tour (rotated files, a
restart that resumed it), and writes:

  -o FILE.html    the report: summary, plots and every tour, in one self-contained
                  file (no network needed to open it)
  --csv FILE      one row per tour, for pandas or R
  --parquet FILE  the same rows as Parquet (lists as list columns, zoned times)
  --json FILE     the totals, the rows and the files skipped
  --compare DIR…  a second season beside the first: every headline figure of the
                  page in both, under its label, and the difference with its 95 %
                  interval

The recordings in one directory are one robot's: give each robot its own. A file that
is not a recording, or is damaged beyond reading, is reported and skipped; one cut
short (kill -9) is read up to the cut. --jobs N reads N files at a time (processes);
--scheduler ADDRESS runs the same work on a dask.distributed cluster. The plots and
Parquet need the `report` extra (matplotlib, pyarrow), the cluster the `fleet` extra
(dask.distributed). Columns and figures: docs/REPORT.md.

  frog-bt report recordings/ -o season.html --csv season.csv --jobs 2
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from frog_bt.commands.options import add_tree_and_config


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "files",
        type=Path,
        nargs="+",
        metavar="FILE_OR_DIR",
        help="recordings: MCAP files, or directories of them",
    )
    add_tree_and_config(p, tree=False)
    p.add_argument(
        "-o", "--output", type=Path, metavar="FILE.html", help="write the HTML report here"
    )
    p.add_argument("--csv", type=Path, metavar="FILE", help="write the rows as CSV")
    p.add_argument("--parquet", type=Path, metavar="FILE", help="write the rows as Parquet")
    p.add_argument(
        "--json", type=Path, metavar="FILE", help="write the totals and the rows as JSON"
    )
    p.add_argument(
        "--compare",
        type=Path,
        nargs="+",
        metavar="FILE_OR_DIR",
        help="a second season (or tree version) to set beside the first",
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="files read at a time, in processes (default 1)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on this dask.distributed scheduler (tcp://HOST:PORT) instead",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _season(
    paths: list[Path], site: Any, pool: Any, bar: Any, quiet: bool = False
) -> tuple[list[Any], list[Any], dict[str, Any], list[str]]:
    """Read one season: facts, rows, totals (with reliability and provenance), skipped."""
    from frog_bt.offline.corpus import recordings
    from frog_bt.offline.report.corpus import read_corpus
    from frog_bt.offline.report.provenance import provenance
    from frog_bt.offline.report.reliability import reliability
    from frog_bt.offline.report.rows import rows as tour_rows
    from frog_bt.offline.report.runs import copies, suspicious
    from frog_bt.offline.report.totals import totals

    facts = read_corpus(recordings(paths), site, pool, bar)
    if bar is not None:
        bar.clear()
    copy = copies([f for f in facts if not f.error])
    facts = [replace(f, error=copy[f.file]) if f.file in copy else f for f in facts]
    skipped = [f"{f.file}: {f.error}" for f in facts if f.error]
    for line in skipped:
        print(f"frog-bt report: skipped {line}", file=sys.stderr)
    for f in facts:
        if f.recovered and not f.error:
            print(f"frog-bt report: {f.file}: {f.recovered}", file=sys.stderr)
        if f.bad and not f.error:
            print(
                f"frog-bt report: {f.file}: {f.bad} message(s) did not decode, read past "
                f"({'; '.join(f.bad_first)})",
                file=sys.stderr,
            )
    read = [f for f in facts if not f.error]
    doubtful = suspicious(read)
    for line in doubtful:
        print(f"frog-bt report: suspicious: {line}", file=sys.stderr)
    rows = tour_rows(read, site)
    face_stops = [s.poi for s in site.tour.stops if s.face_stream]
    order = [s.poi for s in site.tour.stops if s.content]
    t = totals(rows, face_stops, unreadable=len(skipped), order=order)
    t["reliability"] = reliability(read, rows)
    t["provenance"] = provenance(facts, skipped, doubtful)
    return facts, rows, t, skipped


def run(args: argparse.Namespace) -> int:
    from frog_bt.commands.replay import CountBar
    from frog_bt.config import load_site
    from frog_bt.errors import DefinitionError, error_lines
    from frog_bt.offline.corpus import recordings
    from frog_bt.offline.executors import ExecutorError, executor
    from frog_bt.offline.report import outputs
    from frog_bt.offline.report.compare import compare
    from frog_bt.offline.report.intervals import proportion
    from frog_bt.offline.report.precision import estimate

    for wanted, module in (
        (args.output, "matplotlib"),
        (args.parquet, "pyarrow"),
        (True, "scipy"),
    ):
        if wanted and importlib.util.find_spec(module) is None:
            what = "the report" if wanted is True else wanted
            print(f"frog-bt report: {what} needs {module}: {outputs.EXTRA}", file=sys.stderr)
            return 2  # said before reading anything
    if args.jobs < 1:
        print(f"frog-bt report: --jobs {args.jobs}: expected 1 or more", file=sys.stderr)
        return 2
    try:
        site = load_site(args.config)
    except DefinitionError as exc:
        for line in error_lines(exc):
            print(f"frog-bt report: {line}", file=sys.stderr)
        return 2
    other = list(args.compare or [])
    missing = [str(f) for f in [*args.files, *other] if not f.exists()]
    if missing:
        print(f"frog-bt report: no such file or directory: {', '.join(missing)}", file=sys.stderr)
        return 2
    files = recordings(args.files)
    sides = [(args.files, files)] + ([(other, recordings(other))] if other else [])
    for given, found in sides:
        if not found:
            where = ", ".join(str(p) for p in given)
            print(f"frog-bt report: no recordings (*.mcap) found in {where}", file=sys.stderr)
            return 2
    same = {p.resolve() for p in args.files} & {p.resolve() for p in other}
    if same:
        print(
            f"frog-bt report: --compare {', '.join(map(str, sorted(same)))}: the same "
            "recordings on both sides",
            file=sys.stderr,
        )
        return 2
    bar = None if args.quiet or not sys.stderr.isatty() else CountBar(sys.stderr, "report", "files")
    try:
        with executor(args.jobs, args.scheduler) as pool:
            _, rows, t, skipped = _season(args.files, site, pool, bar)
            if other:
                _, _, t_b, _ = _season(other, site, pool, bar)
                name = ", ".join(str(p) for p in args.files)
                t["compare"] = compare(t, t_b, name, ", ".join(str(p) for p in other))
    except ExecutorError as exc:
        print(f"frog-bt report: {exc}", file=sys.stderr)
        return 2
    completion = estimate(proportion(t["rates"]["completion"]), " %")  # to its precision
    print(
        f"frog-bt report: {len(files)} files, {t['tours']} tours, {t['completed']} "
        f"completed ({completion}), {t['resumed']} resumed, {len(skipped)} skipped"
    )
    if other:
        c = t["compare"]
        print(
            f"frog-bt report: --compare: {c['tours'][1]} tours, {c['completed'][1]} completed, "
            f"{len(c['skipped_b'])} skipped"
        )
    try:
        if args.csv:
            outputs.write_csv(rows, args.csv)
        if args.parquet:
            outputs.write_parquet(rows, args.parquet)
        if args.json:
            args.json.write_text(
                json.dumps(
                    {"totals": t, "tours": [r.as_json() for r in rows], "skipped": skipped},
                    indent=1,
                )
                + "\n"
            )
        if args.output:
            outputs.write_html(rows, t, args.output, "FROG tours: what they tell", skipped)
    except outputs.MissingExtra as exc:
        print(f"frog-bt report: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"frog-bt report: cannot write: {exc}", file=sys.stderr)
        return 2
    return 0
