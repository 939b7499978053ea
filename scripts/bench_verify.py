"""How verify's cost grows with the tour: states, transitions, seconds and states per
second for the shipped tree over 6, 30 and 100 stops (the site's stops repeated), from a
fresh start and with the restarts from every checkpoint (what ``frog-bt verify`` does);
with ``--before REV``, side by side with the explorer of an earlier commit, run on the
same machine from an exported copy of it.

    .venv/bin/python scripts/bench_verify.py [--stops 6 30 100] [--limit 200000]
    .venv/bin/python scripts/bench_verify.py --before 78c26e7   # the model explorer

The explorer ticks the loader's nodes in a core with only the world abstracted
(:mod:`frog_bt.verify.real`). Up to 78c26e7 verify explored a model of the tree by
default (``verify/tick.py``: a copy of how the composites tick, over tuples of ints, each
leaf by a table of abstractions); ``--before`` exports that commit (``git archive``)
to a temporary folder and runs its model explorer there (``PYTHONPATH``), one process
per figure, so that both rows come from the same machine in the same minutes. Figures
vary with the load of the machine: run it on a quiet one, or say it was not.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

from frog_bt.behaviours import load_tree
from frog_bt.config import Site, load_site
from frog_bt.verify.explore import TooBig
from frog_bt.verify.model import compile_tree
from frog_bt.verify.real import explore

ROOT = Path(__file__).resolve().parents[1]

# Run in the exported copy of an earlier commit: its model explorer (verify/tick.py).
BEFORE = """
import sys
from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.verify.explore import explore
from frog_bt.verify.model import compile_tree
from frog_bt.verify.properties import Safety

base = load_site(None)
n = int(sys.argv[1])
stops = [base.tour.stops[i % len(base.tour.stops)] for i in range(n)]
site = base.model_copy(update={"tour": base.tour.model_copy(update={"stops": stops})})
model = compile_tree(load_tree(None, site), site)
graph = explore(model, Safety(model))
print(len(graph.states), graph.transitions, graph.seconds)
"""


def sized(base: Site, n: int) -> Site:
    stops = [base.tour.stops[i % len(base.tour.stops)] for i in range(n)]
    return base.model_copy(update={"tour": base.tour.model_copy(update={"stops": stops})})


def row(name: str, states: int, transitions: int, seconds: float) -> str:
    return f"{name:<16} {states:>8} {transitions:>11} {seconds:>8.2f} {states / seconds:>9.0f}"


def real_row(site: Site, limit: int, restarts: bool) -> str:
    name = "real+restarts" if restarts else "real (fresh)"
    model = compile_tree(load_tree(None, site))
    t0 = time.perf_counter()
    try:
        graph, _ = explore(model, site, limit=limit, restarts=restarts)
    except TooBig:
        seconds = time.perf_counter() - t0
        return f"{name:<16} {'>' + str(limit):>8} {'':>11} {seconds:>8.2f}  (stopped at the limit)"
    return row(name, len(graph.states), graph.transitions, graph.seconds)


def export(rev: str, into: Path) -> Path:
    """The tree of commit ``rev`` in ``into`` (``git archive``)."""
    archive = into / "before.tar"
    with archive.open("wb") as out:
        subprocess.run(["git", "-C", str(ROOT), "archive", rev], stdout=out, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(into / "src", filter="data")
    return into / "src"


def before_row(src: Path, rev: str, n: int) -> str:
    env = {**os.environ, "PYTHONPATH": str(src)}
    done = subprocess.run(
        [sys.executable, "-c", BEFORE, str(n)],
        cwd=src,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        return f"{'model ' + rev:<16} failed: {done.stderr.strip().splitlines()[-1:]}"
    states, transitions, seconds = done.stdout.split()
    return row(f"model {rev}", int(states), int(transitions), float(seconds))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stops", type=int, nargs="+", default=[6, 30, 100])
    parser.add_argument("--limit", type=int, default=200_000, help="states, per exploration")
    parser.add_argument("--before", metavar="REV", help="and the explorer of commit REV")
    parser.add_argument("--no-restarts", action="store_true", help="from a fresh start only")
    args = parser.parse_args()
    base = load_site(None)
    print(
        f"{'stops':>5} {'explorer':<16} {'states':>8} {'transitions':>11} {'seconds':>8} "
        f"{'states/s':>9}"
    )
    with tempfile.TemporaryDirectory() as tmp:
        src = export(args.before, Path(tmp)) if args.before else None
        for n in args.stops:
            site = sized(base, n)
            print(f"{n:>5} {real_row(site, args.limit, restarts=False)}", flush=True)
            if not args.no_restarts:
                print(f"{n:>5} {real_row(site, args.limit, restarts=True)}", flush=True)
            if src is not None:
                print(f"{n:>5} {before_row(src, args.before, n)}", flush=True)


if __name__ == "__main__":
    main()
