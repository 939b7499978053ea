"""Telemetry's cost, paired: off and on (and code before/after) alternating, medians.

On a shared machine a single run's figure moves by ±25 % with what else runs. This
runs ``bench_ticks.py`` (or ``bench_reaction.py``) in rounds; in each round every
configuration runs once, one after the other, so that the off and on of a round saw
about the same machine. The overhead is computed per round (on / off of that round)
and its median over the rounds is reported, with the load average at each run.

    .venv/bin/python scripts/bench_ab.py --stops 6,30,100 --rounds 3
    .venv/bin/python scripts/bench_ab.py --before /tmp/main-export   # code before, beside
    .venv/bin/python scripts/bench_ab.py --section reaction --trials 300

``--before DIR`` runs the same bench script with ``PYTHONPATH=DIR`` (a directory holding
a ``frog_bt`` package, e.g. ``git archive <commit> frog_bt | tar -x -C DIR``), so the
code before a change is measured by the same script on the same interpreter.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_support import SCRIPTS, emit


def one(section: str, args: list[str], env: dict[str, str], out: Path) -> dict[str, Any]:
    script = SCRIPTS / f"bench_{section}.py"
    load = os.getloadavg()[0]
    subprocess.run([sys.executable, str(script), *args, "--out", str(out)], env=env, check=True)
    result: dict[str, Any] = json.loads(out.read_text())
    result["load"] = load
    return result


def figure(section: str, result: dict[str, Any]) -> dict[str, float]:
    """The figures compared: the tick p50 (ticks), or the reaction p99 of both kinds."""
    if section == "ticks":
        return {"p50_us": result["all"]["p50_us"], "p99_us": result["all"]["p99_us"]}
    return {
        f"{kind} p99_us": value["p99_us"]
        for kind, value in result.items()
        if isinstance(value, dict) and "p99_us" in value
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--section", choices=("ticks", "reaction"), default="ticks")
    p.add_argument("--stops", default="6,30,100", help="tour sizes")
    p.add_argument("--trials", type=int, default=300, help="trials per run (reaction)")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--configs", default="off,on", help="telemetry settings, first = base")
    p.add_argument("--before", type=Path, help="also run the code in DIR (PYTHONPATH)")
    p.add_argument("--after", type=Path, help="run the code in DIR as 'after' (default: this one)")
    p.add_argument("--out", help="write the JSON result here (default: stdout)")
    args = p.parse_args()
    configs = args.configs.split(",")
    codes: dict[str, dict[str, str]] = {"after": dict(os.environ)}
    if args.after is not None:
        codes["after"]["PYTHONPATH"] = str(args.after.resolve())
    if args.before is not None:
        env = dict(os.environ)
        env["PYTHONPATH"] = str(args.before.resolve())
        codes = {"before": env, **codes}
    sizes = [int(s) for s in args.stops.split(",")]
    runs: dict[str, list[dict[str, Any]]] = {}
    with tempfile.TemporaryDirectory(prefix="frog-ab-") as tmp:
        for r in range(args.rounds):
            for size in sizes:
                for code, env in codes.items():
                    for config in configs:
                        extra = ["--stops", str(size)]
                        if args.section == "reaction":
                            extra += ["--trials", str(args.trials)]
                        key = f"{code} {size} {config}"
                        print(f"round {r + 1}: {key} ...", file=sys.stderr, flush=True)
                        result = one(
                            args.section,
                            [*extra, "--telemetry", config],
                            env,
                            Path(tmp) / "run.json",
                        )
                        rows = runs.setdefault(key, [])
                        rows.append(
                            {
                                **figure(args.section, result),
                                "load": result["load"],
                                "file_bytes": result.get("file_bytes", {}),
                                "telemetry_phases": result.get("telemetry_phases", {}),
                            }
                        )
                        print(f"  {rows[-1]}", file=sys.stderr, flush=True)
    summary: dict[str, Any] = {}
    base = configs[0]
    for key, rows in runs.items():
        code_size, config = key.rsplit(" ", 1)
        entry: dict[str, Any] = {
            name: statistics.median(row[name] for row in rows)
            for name in rows[0]
            if isinstance(rows[0][name], float | int) and name != "load"
        }
        entry["load"] = [round(row["load"], 1) for row in rows]
        if config != base:
            base_rows = runs[f"{code_size} {base}"]
            for name in list(entry):
                if name == "load":
                    continue
                entry[f"{name}_overhead_pct"] = statistics.median(
                    100 * (row[name] / b[name] - 1) for row, b in zip(rows, base_rows, strict=True)
                )
        summary[key] = entry
    emit(
        {"section": args.section, "rounds": args.rounds, "summary": summary, "runs": runs}, args.out
    )
    for key, entry in summary.items():
        print(key, {k: (round(v, 2) if isinstance(v, float) else v) for k, v in entry.items()})


if __name__ == "__main__":
    main()
