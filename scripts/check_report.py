#!/usr/bin/env python3
"""Hold `frog-bt report` over a seeded corpus (scripts/corpus) against its seeding, in all
three outputs: the HTML (parsed: its totals), the CSV and the Parquet rows.

    .venv/bin/python scripts/check_report.py season/ [--jobs 2]

Two kinds of check: the figures the seeded kinds of visitor imply, exactly (a fault
aborts its tour, a bored visitor gets no part b, a decliner and a visitor who wanders
off make a second invitation), and the rates against the seeding weights, within three
binomial standard deviations. Prints one line per check and exits 1 if any fails.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile
from html.parser import HTMLParser
from pathlib import Path


class Totals(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.inside = False
        self.text = ""
        self.images = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        self.inside = tag == "script" and a.get("id") == "totals"
        self.images += tag == "img" and (a.get("src") or "").startswith("data:image/png")

    def handle_data(self, data: str) -> None:
        if self.inside:
            self.text += data


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("corpus", type=Path)
    p.add_argument("--jobs", default="2")
    a = p.parse_args()
    manifest = json.loads((a.corpus / "corpus.json").read_text())
    kinds = [t["kind"] for t in manifest["tours"]]
    weights = manifest["weights"]
    n = len(kinds)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        subprocess.run(
            [
                sys.executable,
                "-m",
                "frog_bt",
                "report",
                str(a.corpus),
                "--jobs",
                a.jobs,
                "--quiet",
                "-o",
                str(out / "r.html"),
                "--csv",
                str(out / "r.csv"),
                "--parquet",
                str(out / "r.parquet"),
            ],
            check=True,
        )
        page = Totals()
        page.feed((out / "r.html").read_text())
        t = json.loads(page.text)
        with open(out / "r.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        import pyarrow.parquet as pq

        parquet = pq.read_table(out / "r.parquet").to_pylist()
    failures = 0

    def check(what: str, got: object, want: object) -> None:
        nonlocal failures
        ok = got == want
        failures += not ok
        shown = f"{len(got)} alike" if isinstance(got, list) and ok and len(got) > 12 else got
        print(f"{'ok  ' if ok else 'FAIL'} {what}: {shown}" + ("" if ok else f" (want {want})"))

    def near(what: str, got: float, p: float, trials: int) -> None:
        nonlocal failures
        sigma = math.sqrt(p * (1 - p) / trials)
        ok = abs(got - p) <= 3 * sigma + 1e-9
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} {what}: {got:.3f}, seeded {p:.3f} (± {3 * sigma:.3f})")

    check("HTML: tours", t["tours"], n)
    check("HTML: plots embedded", page.images >= 5, True)
    check("CSV rows", len(rows), n)
    check(
        "Parquet rows = CSV rows",
        [(r["tour"], r["ended"]) for r in parquet],
        [(int(r["tour"]), r["ended"]) for r in rows],
    )
    check("completed", t["completed"], n - kinds.count("fault"))
    check(
        "aborted tours are the faults",
        [r["ended"] == "aborted" for r in rows],
        [k == "fault" for k in kinds],
    )
    check("invitations", t["invitations"], n + kinds.count("declines") + kinds.count("wander_off"))
    check("invitations declined", t["invitations_declined"], kinds.count("declines"))
    for poi, rate in t["part_b_rate"].items():
        check(
            f"part b at {poi}",
            round(rate * t["gate_decisions"][poi]),
            t["gate_decisions"][poi] - kinds.count("bored"),
        )
    check(
        "tours per day",
        sorted(t["tours_per_day"].values()),
        [manifest["tours_per_day"]] * manifest["days"],
    )
    causes = {(c["cause"], c["detail"]): c["events"] for c in t["failure_causes"]}
    check(
        "failure causes, each event once",
        {k: n for k, n in causes.items() if k[0] != "approach rejected"},
        {
            k: n
            for k, n in {
                ("fault", "motors"): kinds.count("fault"),
                ("invitation declined", ""): kinds.count("declines"),
                ("visitor lost", ""): kinds.count("wander_off"),
                ("navigation retry", ""): kinds.count("nav_failure"),
            }.items()
            if n
        },
    )
    check(
        "funnel: visitors who started",
        t["funnel"]["started"],
        n + kinds.count("wander_off"),
    )
    check("funnel: finished", t["funnel"]["finished"], n - kinds.count("fault"))
    check(
        "failures that needed a person (the faults' alerts)",
        t["reliability"]["failures_needing_a_person"],
        kinds.count("fault"),
    )
    near("completion rate vs seeding", t["completion_rate"], 1 - weights["fault"], n)
    # a visitor who wanders off on the way to POI2 has heard POI1, and the next one
    # hears it again: one more (engaged) visit of POI1 per wanderer
    check(
        "visits of POI1 (the gate's decisions)",
        t["gate_decisions"]["POI1"],
        t["gate_decisions"]["POI2"] + kinds.count("wander_off"),
    )
    for poi, rate in t["part_b_rate"].items():
        extra = weights["wander_off"] if poi == "POI1" else 0.0
        near(
            f"part-b rate at {poi} vs seeding",
            rate,
            1 - weights["bored"] / (1 + extra),
            t["gate_decisions"][poi],
        )
    asked = 1 + weights["declines"] + weights["wander_off"]
    near(
        "invitation acceptance vs seeding",
        t["invitation_acceptance"],
        1 - weights["declines"] / asked,
        t["invitations"],
    )
    print(f"{n} tours: {'all checks hold' if not failures else f'{failures} failed'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
