"""The report's files: per-tour rows as CSV and Parquet, everything as one HTML page.

The HTML is self-contained: the plots are PNG images inside it (``data:`` URLs), the
style is inline, nothing is fetched; it opens offline on any laptop. Plots are drawn
with matplotlib (the ``report`` extra), Parquet written with pyarrow (same extra).
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
from pathlib import Path
from typing import Any

from frog_bt.offline.report.rows import Row

EXTRA = "pip install 'frog-bt[report]'"


class MissingExtra(ImportError):
    """A library of the ``report`` extra is not installed."""


def write_csv(rows: list[Row], path: Path) -> None:
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=Row.columns())
        writer.writeheader()
        for r in rows:
            writer.writerow(r.as_dict())


def write_parquet(rows: list[Row], path: Path) -> None:
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as exc:
        raise MissingExtra(f"--parquet needs pyarrow: {EXTRA}") from exc
    table = pa.Table.from_pylist([r.as_dict() for r in rows])
    pq.write_table(table, path)


def _png(fig: Any) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def plots(rows: list[Row], t: dict[str, Any]) -> list[tuple[str, str]]:
    """(title, data URL) of each plot."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise MissingExtra(f"the HTML report needs matplotlib: {EXTRA}") from exc
    out = []

    def bar(
        title: str, data: dict[Any, float], xlabel: str, ylabel: str, rotate: bool = False
    ) -> None:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.bar([str(k) for k in data], list(data.values()), color="#3a6ea5")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if rotate:
            ax.tick_params(axis="x", labelrotation=45)
        ax.grid(axis="y", alpha=0.3)
        out.append((title, _png(fig)))
        plt.close(fig)

    def hist(title: str, values: list[float], xlabel: str) -> None:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.hist(values, bins=20, color="#3a6ea5")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("tours")
        ax.grid(axis="y", alpha=0.3)
        out.append((title, _png(fig)))
        plt.close(fig)

    bar("Tours per day", t["tours_per_day"], "day", "tours", rotate=True)
    bar(
        "Tours per hour of the day",
        {f"{h}:00": n for h, n in t["tours_per_hour"].items()},
        "hour (local time)",
        "tours",
    )
    rates = {poi: 100 * r for poi, r in t["part_b_rate"].items() if r is not None}
    if rates:
        bar("Part b played (the engagement gate)", rates, "stop", "% of visits")
    hist("Tour length", [r.duration_s / 60 for r in rows], "minutes")
    stop_times: dict[str, list[float]] = {}
    for r in rows:
        for poi, s in json.loads(r.time_at_stops).items():
            stop_times.setdefault(poi, []).append(s)
    if stop_times:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.boxplot(list(stop_times.values()))
        ax.set_xticks(range(1, len(stop_times) + 1), list(stop_times))
        ax.set_ylabel("seconds")
        ax.grid(axis="y", alpha=0.3)
        out.append(("Time at each stop", _png(fig)))
        plt.close(fig)
    bar(
        "Distance driven per day",
        {d: m / 1000 for d, m in t["distance_per_day_m"].items()},
        "day",
        "km",
        rotate=True,
    )
    return out


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def write_html(
    rows: list[Row], t: dict[str, Any], path: Path, title: str, skipped: list[str]
) -> None:
    e = html.escape
    figures = plots(rows, t)
    tour_min = t["tour_minutes"] or {}
    summary = [
        (
            "Tours",
            f"{t['tours']} ({t['completed']} completed, {t['resumed']} resumed after a restart)",
        ),
        ("Completion rate", _pct(t["completion_rate"])),
        ("Approach success", f"{_pct(t['approach_success'])} of {t['approaches']} approaches"),
        (
            "Invitation acceptance",
            f"{_pct(t['invitation_acceptance'])} of "
            f"{t['invitations']} invitations "
            f"({t['invitations_declined']} declined)",
        ),
        ("Visitors reached", f"{t['visitors']} (said yes to a tour)"),
        *(
            (f"Part b at {poi}", f"{_pct(r)} of {t['gate_decisions'][poi]} visits")
            for poi, r in t["part_b_rate"].items()
        ),
        (
            "Tour length",
            f"median {tour_min.get('median', '-')} min "
            f"(from {tour_min.get('min', '-')} to {tour_min.get('max', '-')})",
        ),
        ("Distance driven", f"{t['distance_m'] / 1000:.1f} km"),
        (
            "Time-of-day variants",
            ", ".join(f"{k} {n}" for k, n in sorted(t["variants"].items())) or "none",
        ),
        ("Files skipped", str(len(skipped))),
    ]
    causes = (
        "".join(
            f"<tr><td>{e(c)}</td><td class=n>{n}</td></tr>" for c, n in t["failure_causes"].items()
        )
        or "<tr><td>none</td></tr>"
    )
    cols = [
        "tour",
        "robot",
        "start",
        "duration_s",
        "distance_m",
        "stops_visited",
        "stops_skipped",
        "visitors",
        "introduction",
        "parts",
        "ended",
        "reason",
        "resumed",
    ]
    body = "".join(
        "<tr>" + "".join(f"<td>{e(str(getattr(r, c)))}</td>" for c in cols) + "</tr>" for r in rows
    )
    data = json.dumps(t).replace("</", "<\\/")  # raw text inside <script>: no entities
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{e(title)}</title>
<style>
body {{ font: 15px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 72em;
        padding: 0 1em; color: #1d2733; }}
h1 {{ font-size: 1.6em; }} h2 {{ font-size: 1.2em; margin-top: 2em; }}
table {{ border-collapse: collapse; }} td, th {{ padding: .25em .7em; text-align: left;
        border-bottom: 1px solid #dde3ea; vertical-align: top; }}
td.n {{ text-align: right; }} .figs {{ display: flex; flex-wrap: wrap; gap: 1em; }}
figure {{ margin: 0; }} figcaption {{ font-weight: 600; }} img {{ max-width: 100%; }}
.tours td {{ font-size: .85em; }} .skip {{ color: #8a4b00; }}
.wide {{ overflow-x: auto; }}
</style></head><body>
<h1>{e(title)}</h1>
<h2>Summary</h2>
<table id="summary">{"".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in summary)}
</table>
<h2>Plots</h2>
<div class="figs">{
        "".join(
            f'<figure><figcaption>{e(name)}</figcaption><img alt="{e(name)}" src="{url}"></figure>'
            for name, url in figures
        )
    }</div>
<h2>Most frequent failure causes</h2>
<table id="causes">{causes}</table>
<h2>Tours</h2>
<div class="wide"><table class="tours" id="tours"><tr>{"".join(f"<th>{c}</th>" for c in cols)}</tr>
{body}</table></div>
{"".join(f'<p class="skip">skipped: {e(s)}</p>' for s in skipped)}
<script type="application/json" id="totals">{data}</script>
</body></html>
"""
    path.write_text(page, encoding="utf-8")
