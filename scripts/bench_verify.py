"""How verify's cost grows with the tour, both explorers side by side: states, transitions,
seconds and states per second for the shipped tree over 6, 30 and 100 stops (the site's
stops repeated), and the model's per-property times.

    .venv/bin/python scripts/bench_verify.py [--stops 6 30 100] [--real-limit 20000]

The model explorer (:mod:`frog_bt.verify.tick`) ticks a copy of the tree over tuples of
ints; the real one (``verify --real``, :mod:`frog_bt.verify.real`) ticks the loader's
nodes in a core with only the world abstracted, from a fresh start (``--restarts``: and
from every checkpoint the tree writes, as ``verify --real`` does), and stops at
``--real-limit`` states.
"""

from __future__ import annotations

import argparse
import time

from frog_bt.behaviours import load_tree
from frog_bt.config import Site, load_site
from frog_bt.verify import designer
from frog_bt.verify.explore import TooBig, explore
from frog_bt.verify.model import compile_tree
from frog_bt.verify.properties import Safety, bounded_retries, ends_well, home_obeyed, no_dead_reads
from frog_bt.verify.real import explore_real


def model_row(site: Site) -> str:
    tree = load_tree(None, site)
    model = compile_tree(tree, site)
    safety = Safety(model)
    graph = explore(model, safety)
    times = {}
    for name, check in (
        ("ends-well", ends_well),
        ("bounded-retries", bounded_retries),
        ("home-obeyed", home_obeyed),
        ("no-dead-reads", no_dead_reads),
    ):
        t0 = time.perf_counter()
        check(graph, model)  # type: ignore[operator]
        times[name] = time.perf_counter() - t0
    designer.read_properties(tree.file)
    per = ", ".join(f"{k} {v:.2f}" for k, v in times.items())
    rate = len(graph.states) / graph.seconds
    return (
        f"model {len(graph.states):>8} {graph.transitions:>10} {graph.seconds:>8.2f} "
        f"{rate:>8.0f}  ({per})"
    )


def real_row(site: Site, limit: int, restarts: bool) -> str:
    tree = load_tree(None, site)
    model = compile_tree(tree, site, real=True)
    t0 = time.perf_counter()
    try:
        graph, _ = explore_real(model, site, limit=limit, restarts=restarts)
    except TooBig:
        seconds = time.perf_counter() - t0
        return (
            f"real  {'>' + str(limit):>8} {'':>10} {seconds:>8.2f} {limit / seconds:>8.0f}  "
            "(stopped at the limit)"
        )
    rate = len(graph.states) / graph.seconds
    return (
        f"real  {len(graph.states):>8} {graph.transitions:>10} {graph.seconds:>8.2f} {rate:>8.0f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stops", type=int, nargs="+", default=[6, 30, 100])
    parser.add_argument("--real-limit", type=int, default=100000)
    parser.add_argument(
        "--restarts", action="store_true", help="the real explorer from every checkpoint too"
    )
    args = parser.parse_args()
    base = load_site(None)
    print(f"{'stops':>5} {'':5} {'states':>8} {'transitions':>10} {'seconds':>8} {'states/s':>8}")
    for n in args.stops:
        stops = [base.tour.stops[i % len(base.tour.stops)] for i in range(n)]
        site = base.model_copy(update={"tour": base.tour.model_copy(update={"stops": stops})})
        print(f"{n:>5} {model_row(site)}")
        print(f"{n:>5} {real_row(site, args.real_limit, args.restarts)}")


if __name__ == "__main__":
    main()
