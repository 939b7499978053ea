"""``scripts/bench``: run every section, print the figures against the budgets, write JSON.

Each section runs in a fresh process (``scripts/bench_<section>.py --out FILE``), one
after the other, so that no section inherits another's imports, memory or threads.
Budgets are goals read off the table; nothing here fails because one is missed
(the exit status is non-zero only when a section could not run).
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from bench_support import SCRIPTS, summary_us

SECTIONS = ("startup", "ticks", "reaction", "ingest", "replay", "memory", "console", "report")
PHASES = ("waiting", "undocking", "recruiting", "driving", "content", "returning", "other")


TICK_ROUNDS = 5  # tours of each size, off and on in turns: the overhead is paired
REACTION_ROUNDS = 2  # reaction runs of each size and setting, off and on in turns
ROUND = "#"  # a run's label: "{stops}-{telemetry}#{round}"


def combine_rounds(
    runs: dict[str, Any], combine: Callable[[list[dict[str, Any]]], dict[str, Any]]
) -> dict[str, Any]:
    """The runs of each size and setting (labels ``{stops}-{telemetry}#{round}``) made
    one by ``combine`` (their rounds, in order); a failed round stands for all of them."""
    groups: dict[str, list[dict[str, Any]]] = {}
    for label, run in runs.items():
        groups.setdefault(label.split(ROUND)[0], []).append(run)
    combined: dict[str, Any] = {}
    for label, rounds in groups.items():
        failed = [r for r in rounds if "error" in r]
        combined[label] = failed[0] if failed else combine(rounds)
    return combined


def median_round(rounds: list[dict[str, Any]]) -> dict[str, Any]:
    """Tick runs: the round with the median tick p50 stands for them (its phases, files,
    telemetry), with every round's p50 beside it (``rounds_p50_us``, in order) and the
    batches dropped summed over the rounds."""
    p50s = [get(r, "all", "p50_us") for r in rounds]
    order = sorted(range(len(rounds)), key=lambda i: p50s[i] or 0.0)
    run = dict(rounds[order[len(order) // 2]])
    run["rounds_p50_us"] = p50s
    drops = [r.get("telemetry_dropped_batches") for r in rounds]
    if any(d is not None for d in drops):
        run["telemetry_dropped_batches"] = sum(d or 0 for d in drops)
    return run


def pooled_trials(rounds: list[dict[str, Any]]) -> dict[str, Any]:
    """Reaction runs: each kind's figures over the trials of every round (``rounds``: how
    many), the raw trials left out of the JSON."""
    run = {k: v for k, v in rounds[0].items() if k != "samples_ns"}
    run["rounds"] = len(rounds)
    run["trials"] = sum(r.get("trials", 0) for r in rounds)
    run["errors"] = [e for r in rounds for e in r.get("errors", [])][:5]
    pooled: dict[str, dict[str, list[int]]] = {"measured": {}, "read": {}}
    for r in rounds:
        for which, kinds in pooled.items():
            for kind, values in (get(r, "samples_ns", which) or {}).items():
                kinds.setdefault(kind, []).extend(values)
    run.update({kind: summary_us(v) for kind, v in pooled["measured"].items()})
    run["read by the robot"] = {kind: summary_us(v) for kind, v in pooled["read"].items()}
    return run


def overhead_pct(ticks: dict[str, Any], n: int) -> float | None:
    """Telemetry's cost on the tick p50 at ``n`` stops, in %: the median over the paired
    rounds of on / off - 1 (one round: that round's)."""
    on, off = ticks.get(f"{n}-on", {}), ticks.get(f"{n}-off", {})
    pairs = [
        (a, b)
        for a, b in zip(on.get("rounds_p50_us", []), off.get("rounds_p50_us", []), strict=False)
        if a and b
    ]
    if not pairs:
        a, b = get(on, "all", "p50_us"), get(off, "all", "p50_us")
        return None if a is None or not b else 100 * (float(a) / float(b) - 1)
    ratios = sorted(100 * (float(a) / float(b) - 1) for a, b in pairs)
    return ratios[len(ratios) // 2]


def plan(quick: bool, sizes: tuple[int, ...] = ()) -> dict[str, list[tuple[str, list[str]]]]:
    """Section -> runs: (name, arguments of its script); ``sizes``: the tours' stops."""
    sizes = sizes or ((6, 30) if quick else (6, 30, 100))
    return {
        "startup": [("startup", ["--runs", "3" if quick else "7", "--telemetry"])],
        "ticks": [  # off and on in turns, the order swapped each round (paired rounds)
            (f"{n}-{t}{ROUND}{r}", ["--stops", str(n), "--telemetry", t])
            for n in sizes
            for r in range(1 if quick else TICK_ROUNDS)
            for t in (("off", "on") if r % 2 == 0 else ("on", "off"))
        ],
        "reaction": [  # off and on in turns; the trials of the rounds pooled
            (
                f"{n}-{t}{ROUND}{r}",
                [
                    "--stops",
                    str(n),
                    "--trials",
                    "200" if quick else str(1000 // REACTION_ROUNDS),
                    "--telemetry",
                    t,
                ],
            )
            for n in sizes
            for r in range(1 if quick else REACTION_ROUNDS)
            for t in (("off", "on") if r % 2 == 0 else ("on", "off"))
        ],
        "ingest": [("ingest", ["--seconds", "1" if quick else "5"])],
        "replay": [("replay", ["--minutes", "10" if quick else "60"])],
        "memory": [("off", ["--tours", "10" if quick else "100"])]
        + ([] if quick else [("on", ["--tours", "30", "--telemetry", "on"])]),
        "console": [("console", ["--clients", "10", "--runs", "1" if quick else "3"])],
        "report": [
            ("report", ["--tours", "20" if quick else "100", "--runs", "1" if quick else "2"])
        ],
    }


def run_section(name: str, runs: list[tuple[str, list[str]]], tmp: Path) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for label, args in runs:
        target = tmp / f"{name}-{label}.json"
        t0 = time.monotonic()
        print(f"  {name} {label} ...", end="", file=sys.stderr, flush=True)
        done = subprocess.run(
            [sys.executable, str(SCRIPTS / f"bench_{name}.py"), *args, "--out", str(target)],
            capture_output=True,
            text=True,
        )
        print(f" {time.monotonic() - t0:.0f} s", file=sys.stderr, flush=True)
        if done.returncode != 0 or not target.exists():
            out[label] = {"error": (done.stderr or done.stdout)[-3000:]}
            print(
                f"    failed: {(done.stderr or done.stdout).strip().splitlines()[-1:]}",
                file=sys.stderr,
            )
            continue
        out[label] = json.loads(target.read_text(encoding="utf-8"))
    return out


def machine() -> dict[str, Any]:
    model = ""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            model = next(
                (line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), ""
            )
    except OSError:
        pass
    return {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
        "cpu_model": model,
        "load_before": os.getloadavg() if hasattr(os, "getloadavg") else None,
    }


# ------------------------------------------------------------------ budgets


def get(data: dict[str, Any], *path: str) -> Any:
    for key in path:
        if not isinstance(data, dict) or key not in data:
            return None
        data = data[key]
    return data


class Rows:
    """The budget table: (what, figure, budget, met) rows."""

    def __init__(self) -> None:
        self.rows: list[dict[str, Any]] = []

    def add(
        self,
        what: str,
        value: float | None,
        unit: str,
        budget: str,
        met: Callable[[float], bool] | None,
        fmt: str = "{:.0f}",
    ) -> None:
        ok = None if value is None or met is None else bool(met(value))
        text = "n/a" if value is None else fmt.format(value) + unit
        self.rows.append(
            {
                "what": what,
                "value": value,
                "unit": unit.strip(),
                "text": text,
                "budget": budget,
                "met": ok,
            }
        )


def budgets(results: dict[str, Any]) -> list[dict[str, Any]]:
    rows = Rows()
    ticks = results.get("ticks", {})
    sizes = sorted({int(k.split("-")[0]) for k in ticks})
    for n in sizes:
        on = get(ticks, f"{n}-on", "all", "p50_us")
        stops = f"{n} stops, {get(ticks, f'{n}-on', 'nodes') or '?'} nodes"
        rows.add(f"tick p50, telemetry on ({stops})", on, " µs", "≤ 150 µs", lambda v: v <= 150)
        overhead = overhead_pct(ticks, n)
        if overhead is not None:
            rounds = len(get(ticks, f"{n}-on", "rounds_p50_us") or [None])
            rows.add(
                f"telemetry overhead on tick p50 ({n} stops"
                + (f", median of {rounds} paired rounds)" if rounds > 1 else ")"),
                overhead,
                " %",
                "≤ 10 %",
                lambda v: v <= 10,
            )
        rows.add(
            f"telemetry writing after the ticks, per tick ({n} stops)",
            get(ticks, f"{n}-on", "telemetry_write_us_per_tick"),
            " µs",
            "(off the tick)",
            None,
        )
        rows.add(  # a figure bought by dropping telemetry is no figure
            f"telemetry batches dropped ({n} stops)",
            get(ticks, f"{n}-on", "telemetry_dropped_batches"),
            "",
            "= 0",
            lambda v: v == 0,
            "{:.0f}",
        )
    if len(sizes) > 1:
        small, large = sizes[0], sizes[-1]
        for t in ("off", "on"):
            a = get(ticks, f"{small}-{t}", "all", "p50_us")
            b = get(ticks, f"{large}-{t}", "all", "p50_us")
            if a and b:
                rows.add(
                    f"tick p50 {large} vs {small} stops, telemetry {t}",
                    b / a,
                    " x",
                    "≈ 1 x (active path)",
                    lambda v: v <= 1.25,
                    "{:.2f}",
                )
    for run in results.get("reaction", {}):
        n, t = run.split("-")
        for kind in ("response 2 -> start_poi", "user_positive -> /GotoWayPoint"):
            value = get(results, "reaction", run, kind, "p99_us")
            rows.add(
                f"reaction p99 {kind}, telemetry {t} ({n} stops)",
                None if value is None else value / 1000,
                " ms",
                "≤ 2 ms",
                lambda v: v <= 2,
                "{:.2f}",
            )
            read = get(results, "reaction", run, "read by the robot", kind, "p99_us")
            rows.add(  # the same, to when the fake robot read it: its own wake-up too
                f"  the same, read by the robot ({t}, {n} stops)",
                None if read is None else read / 1000,
                " ms",
                "",
                None,
                "{:.2f}",
            )
    ingest = get(results, "ingest", "ingest") or {}
    for kind in ("pose", "faces", "persons") if ingest else ():
        ours = get(ingest, "executive", kind, "msg_per_s")
        theirs = get(ingest, "roslibpy", kind, "msg_per_s")
        rows.add(
            f"ingestion, {kind} flood",
            ours,
            " msg/s",
            "≥ 5,000 msg/s",
            lambda v: v >= 5000,
            "{:,.0f}",
        )
        if ours and theirs:
            rows.add(
                f"ingestion vs roslibpy, {kind} flood",
                ours / theirs,
                " x",
                "≥ 2 x",
                lambda v: v >= 2,
                "{:.2f}",
            )
    if "replay" in results:
        minutes = (get(results, "replay", "replay", "recording", "sim_s") or 0) / 60
        for key, label in (
            ("plain", f"replay of {minutes:.0f} recorded minutes"),
            ("rrd", f"replay of {minutes:.0f} recorded minutes, with .rrd"),
        ):
            rows.add(
                label,
                get(results, "replay", "replay", key, "command_speed_x"),
                " x real time",
                "≥ 500 x",
                lambda v: v >= 500,
            )
    if "startup" in results:
        for stat in ("p50", "max"):
            rows.add(
                f"start-up to connected and subscribed, {stat}",
                get(results, "startup", "startup", "plain", stat),
                " s",
                "≤ 0.5 s" if stat == "p50" else "",
                (lambda v: v <= 0.5) if stat == "p50" else None,
                "{:.2f}",
            )
        rows.add(
            "start-up with --record and --rerun save:, p50",
            get(results, "startup", "startup", "telemetry", "p50"),
            " s",
            "≤ 0.7 s",
            lambda v: v <= 0.7,
            "{:.2f}",
        )
    mem = get(results, "memory", "off") or {}
    if "growth_pct" in mem:
        rows.add(
            f"RSS growth, tour 1 -> {mem['tours']} ({mem['rss_first_kb'] / 1024:.1f} -> "
            f"{mem['rss_last_kb'] / 1024:.1f} MiB)",
            mem["growth_pct"],
            " %",
            "≤ 5 %",
            lambda v: v <= 5,
            "{:.1f}",
        )
    mem_on = get(results, "memory", "on") or {}
    if "growth_pct" in mem_on:
        rows.add(
            f"RSS growth with telemetry, tour 1 -> {mem_on['tours']} "
            f"({mem_on['rss_first_kb'] / 1024:.1f} -> {mem_on['rss_last_kb'] / 1024:.1f}"
            " MiB)",
            mem_on["growth_pct"],
            " %",
            "≤ 5 %",
            lambda v: v <= 5,
            "{:.1f}",
        )
    console = get(results, "console", "console") or {}
    if "overhead_pct" in console:
        rows.add(
            f"console overhead on tick p50, {console['clients']} pages",
            console["overhead_pct"],
            " %",
            "≤ 5 %",
            lambda v: v <= 5,
            "{:.1f}",
        )
        rows.add(
            "console: a new phase reaches every page, max",
            console["latency_max_ms"],
            " ms",
            "≤ 500 ms",
            lambda v: v <= 500,
            "{:.1f}",
        )
    rep = get(results, "report", "report") or {}
    if "report_vs_plain_read" in rep:
        rows.add(
            f"report throughput vs reading every message with mcap ({rep['tours']} tours)",
            100 * rep["report_vs_plain_read"],
            " %",
            "≥ 50 %",
            lambda v: v >= 50,
            "{:.0f}",
        )
        rows.add(
            "report --jobs 2 vs one job",
            rep["two_jobs_speedup"],
            " x",
            "≥ 1.6 x",
            lambda v: v >= 1.6,
            "{:.2f}",
        )
    return rows.rows


# ------------------------------------------------------------------ printing


def table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [
        max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)
    ]
    line = "  ".join(f"{{:<{w}}}" for w in widths)
    out = [line.format(*headers), line.format(*("-" * w for w in widths))]
    out += [line.format(*r) for r in rows]
    return "\n".join(out)


def report(results: dict[str, Any], rows: list[dict[str, Any]]) -> str:
    parts = ["", "Budgets (goals read off this table, never asserted)", ""]
    mark = {True: "met", False: "MISSED", None: "-"}
    parts.append(
        table(
            ["what", "figure", "budget", ""],
            [[r["what"], r["text"], r["budget"], mark[r["met"]]] for r in rows],
        )
    )
    ticks = results.get("ticks", {})
    if ticks:
        labels = [k for k in ticks if "all" in ticks[k]]
        body = []
        for phase in (*PHASES, "all"):
            cells = []
            for k in labels:
                s = ticks[k]["all"] if phase == "all" else ticks[k]["phases"].get(phase)
                cells.append(f"{s['p50_us']:.0f} / {s['p99_us']:.0f} ({s['n']})" if s else "-")
            if any(c != "-" for c in cells):
                body.append([phase, *cells])
        heads = ["tick µs p50 / p99 (n)"] + [
            f"{k.split('-')[0]} stops, tel. {k.split('-')[1]}" for k in labels
        ]
        parts += ["", table(heads, body)]
    phases = [(k, ticks[k].get("telemetry_phases")) for k in ticks if "-on" in k]
    phases = [(k, p) for k, p in phases if p]
    if phases:
        off = {k: get(ticks, k.replace("-on", "-off"), "all", "p50_us") for k, _ in phases}
        body = [
            [
                f"{k.split('-')[0]} stops",
                f"{ticks[k]['all']['p50_us'] - off[k]:+.1f}" if off[k] else "n/a",
                f"{p['serialise'].get('p50_us', 0):.0f} / {p['serialise'].get('max_us', 0):.0f}",
                "{:.0f} / {:.0f}".format(
                    p.get("serialise_step", {}).get("p50_us", 0),
                    p.get("serialise_step", {}).get("max_us", 0),
                ),
                f"{p['hand_over'].get('p50_us', 0):.0f} / {p['hand_over'].get('max_us', 0):.0f}",
                f"{p['write_us_per_batch']:.0f}",
                f"{p['batches']}",
            ]
            for k, p in phases
        ]
        parts += [
            "",
            "Telemetry by phase (--record and --rerun save:; a batch is 50 ticks)",
            table(
                [
                    "tour",
                    "on the tick: p50 µs",
                    "serialise µs/batch p50 / max",
                    "of it in one step µs p50 / max",
                    "hand over µs p50 / max",
                    "write µs/batch (child CPU)",
                    "batches",
                ],
                body,
            ),
        ]
    ingest = get(results, "ingest", "ingest") or {}
    if ingest.get("executive"):
        body = []
        for kind in ("pose", "faces", "persons"):
            e, r = ingest["executive"].get(kind, {}), (ingest.get("roslibpy") or {}).get(kind, {})
            body.append(
                [
                    kind,
                    f"{e.get('msg_per_s', 0):,.0f}",
                    f"{e.get('ticks_per_s', 0):.0f}",
                    f"{e.get('rss_before_kb', 0) / 1024:.1f} -> "
                    f"{e.get('rss_after_kb', 0) / 1024:.1f}",
                    f"{r['msg_per_s']:,.0f}" if r else "n/a",
                ]
            )
        parts += [
            "",
            table(["flood", "executive msg/s", "ticks/s", "RSS MiB", "roslibpy msg/s"], body),
        ]
        skipped = get(ingest, "roslibpy", "skipped")
        if skipped:
            parts.append(f"(no roslibpy column: {skipped})")
    return "\n".join(parts)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="scripts/bench", description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="smaller samples: about a minute")
    p.add_argument(
        "--json",
        type=Path,
        default=Path("bench.json"),
        metavar="PATH",
        help="where to write the results (default: bench.json)",
    )
    p.add_argument(
        "--only",
        metavar="SECTION[,SECTION]",
        help=f"run only these sections ({', '.join(SECTIONS)})",
    )
    p.add_argument(
        "--stops",
        metavar="N[,N]",
        help="tour sizes for ticks and reaction (default: 6,30 with --quick, else 6,30,100)",
    )
    args = p.parse_args(argv)
    sizes = tuple(int(n) for n in args.stops.split(",")) if args.stops else ()
    chosen = SECTIONS if not args.only else tuple(s for s in args.only.split(",") if s)
    unknown = [s for s in chosen if s not in SECTIONS]
    if unknown:
        p.error(f"unknown section {unknown[0]!r} (known: {', '.join(SECTIONS)})")
    started = time.monotonic()
    results: dict[str, Any] = {
        "machine": machine(),
        "quick": args.quick,
        "started": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
    }
    print(
        f"frog-bt bench{' --quick' if args.quick else ''} on {results['machine']['cpus']} "
        f"CPUs ({results['machine']['cpu_model'] or platform.machine()})",
        file=sys.stderr,
    )
    failed = False
    with tempfile.TemporaryDirectory(prefix="frog-bench-") as tmp:
        for name, runs in plan(args.quick, sizes).items():
            if name in chosen:
                results[name] = run_section(name, runs, Path(tmp))
                if name == "ticks":
                    results[name] = combine_rounds(results[name], median_round)
                elif name == "reaction":
                    results[name] = combine_rounds(results[name], pooled_trials)
                failed |= any("error" in r for r in results[name].values())
    results["machine"]["load_after"] = os.getloadavg() if hasattr(os, "getloadavg") else None
    results["wall_s"] = time.monotonic() - started
    rows = budgets(results)
    results["budgets"] = rows
    args.json.write_text(json.dumps(results, indent=1, default=str) + "\n", encoding="utf-8")
    print(report(results, rows))
    print(f"\n{results['wall_s']:.0f} s; results in {args.json}")
    return 1 if failed else 0
