"""How verify's cost grows with the tour: states, transitions and seconds for the shipped
tree over 6, 30 and 100 stops (the site's stops repeated), and per property.

    .venv/bin/python scripts/bench_verify.py [--stops 6 30 100]

Stops are alike and a stop's state is cleared as the next starts, so the states grow
linearly with the number of stops (no symmetry reduction is needed); the time per state
is flat.
"""

from __future__ import annotations

import argparse
import time

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.verify import designer
from frog_bt.verify.explore import explore
from frog_bt.verify.model import compile_tree
from frog_bt.verify.properties import Safety, bounded_retries, ends_well, home_obeyed, no_dead_reads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stops", type=int, nargs="+", default=[6, 30, 100])
    args = parser.parse_args()
    base = load_site(None)
    print(f"{'stops':>6} {'states':>8} {'transitions':>12} {'explore s':>10}  per property (s)")
    for n in args.stops:
        stops = [base.tour.stops[i % len(base.tour.stops)] for i in range(n)]
        site = base.model_copy(update={"tour": base.tour.model_copy(update={"stops": stops})})
        tree = load_tree(None, site)
        model = compile_tree(tree, site)
        safety = Safety(model)
        graph = explore(model, safety)
        times = {"safety (5, during the search)": 0.0}
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
        print(
            f"{n:>6} {len(graph.states):>8} {graph.transitions:>12} {graph.seconds:>10.2f}  {per}"
        )


if __name__ == "__main__":
    main()
