"""The report's files: per-tour rows as CSV and Parquet, everything as one HTML page.

The HTML is self-contained: the plots are PNG images inside it (``data:`` URLs), the
style is inline, nothing is fetched; it opens offline on any laptop. Plots are drawn
with matplotlib (the ``report`` extra), Parquet written with pyarrow (same extra).
"""

from __future__ import annotations

import base64
import csv
import dataclasses
import io
import types
import typing
from datetime import date, datetime
from pathlib import Path
from typing import Any

from frog_bt.clock import SITE_TZ
from frog_bt.offline.report.rows import Row

EXTRA = "pip install 'frog-bt[report]'"


class MissingExtra(ImportError):
    """A library of the ``report`` extra is not installed."""


def write_csv(rows: list[Row], path: Path) -> None:
    """One row per tour, one plain column per figure (lists joined with '; ')."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=Row.columns())
        writer.writeheader()
        for r in rows:
            writer.writerow(r.as_text())


def _arrow_type(pa: Any, hint: Any) -> Any:
    """The Arrow type of a Row field's Python type (one declaration: the dataclass)."""
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    origin = typing.get_origin(hint)
    if origin is list:
        return pa.list_(_arrow_type(pa, args[0]))
    if origin in (types.UnionType, typing.Union):
        return _arrow_type(pa, args[0])
    if dataclasses.is_dataclass(hint):
        hints = typing.get_type_hints(hint)
        return pa.struct(
            [(f.name, _arrow_type(pa, hints[f.name])) for f in dataclasses.fields(hint)]
        )
    if hint is datetime:
        return pa.timestamp("us", tz=SITE_TZ.key)
    simple = {bool: pa.bool_(), int: pa.int64(), float: pa.float64(), date: pa.date32()}
    return simple.get(hint, pa.string())  # str, and str enums


def parquet_schema(pa: Any) -> Any:
    hints = typing.get_type_hints(Row)
    return pa.schema([(f.name, _arrow_type(pa, hints[f.name])) for f in dataclasses.fields(Row)])


def write_parquet(rows: list[Row], path: Path) -> None:
    """The rows with lists as list columns, ``day`` a date, ``start`` a zoned timestamp."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as exc:
        raise MissingExtra(f"--parquet needs pyarrow: {EXTRA}") from exc
    table = pa.Table.from_pylist([r.as_dict() for r in rows], schema=parquet_schema(pa))
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

    from matplotlib.ticker import MaxNLocator

    def bar(
        title: str,
        data: dict[Any, float],
        xlabel: str,
        ylabel: str,
        rotate: bool = False,
        counts: bool = False,
    ) -> None:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.bar([str(k) for k in data], list(data.values()), color="#3a6ea5")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if rotate:
            ax.tick_params(axis="x", labelrotation=45)
        if counts:  # whole tours, visitors: no 0.5 on the axis
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(axis="y", alpha=0.3)
        out.append((title, _png(fig)))
        plt.close(fig)

    def hist(title: str, values: list[float], xlabel: str) -> None:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.hist(values, bins=20, color="#3a6ea5")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("tours")
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(axis="y", alpha=0.3)
        out.append((title, _png(fig)))
        plt.close(fig)

    bar("Tours per day", t["tours_per_day"], "day", "tours", rotate=True, counts=True)
    bar(
        "Tours per hour of the day",
        {f"{h}:00": n for h, n in t["tours_per_hour"].items()},
        "hour (local time)",
        "tours",
        rotate=True,
        counts=True,
    )
    rates = {poi: 100 * r for poi, r in t["part_b_rate"].items() if r is not None}
    if rates:
        bar("Part b played (the engagement gate)", rates, "stop", "% of visits")
    hist("Tour length", [r.duration_s / 60 for r in rows], "minutes")
    stop_times: dict[str, list[float]] = {}
    for r in rows:
        for st in r.time_at_stops:
            stop_times.setdefault(st.poi, []).append(st.seconds)
    if stop_times:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        ax.boxplot(list(stop_times.values()))
        ax.set_xticks(range(1, len(stop_times) + 1), list(stop_times))
        ax.set_ylabel("seconds")
        ax.grid(axis="y", alpha=0.3)
        out.append(("Time at each stop", _png(fig)))
        plt.close(fig)
    if t["funnel"]:
        bar("Where visitors drop out", t["funnel"], "stop", "visitors", rotate=True, counts=True)
    days = t["per_day"]
    if days:
        fig, ax = plt.subplots(figsize=(5.2, 2.7))
        for name, key in (("completion", "completion"), ("part b", "part_b")):
            daily = [d[key] for d in days.values()]
            xs = [i for i, r in enumerate(daily) if r["rate"] is not None]
            ys = [100 * daily[i]["rate"] for i in xs]
            lo = [100 * (daily[i]["rate"] - daily[i]["low"]) for i in xs]
            hi = [100 * (daily[i]["high"] - daily[i]["rate"]) for i in xs]
            ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", capsize=3, label=name)
        ax.set_xticks(range(len(days)), list(days), rotation=45)
        ax.set_ylabel("% (95 % interval)")
        ax.set_ylim(top=118)  # room above 100 % for the legend, clear of the bars
        ax.legend(loc="upper center", ncols=2, frameon=False)
        ax.grid(axis="y", alpha=0.3)
        out.append(("Per day: completion and part b", _png(fig)))
        plt.close(fig)
    bar(
        "Distance driven per day",
        {d: m / 1000 for d, m in t["distance_per_day_m"].items()},
        "day",
        "km",
        rotate=True,
    )
    return out


def write_html(
    rows: list[Row],
    t: dict[str, Any],
    path: Path,
    title: str,
    skipped: list[str],
    extra: str = "",
) -> None:
    """The page (:mod:`frog_bt.offline.report.page`) with this module's plots."""
    from frog_bt.offline.report.page import page

    path.write_text(page(rows, t, plots(rows, t), title, skipped, extra), encoding="utf-8")
