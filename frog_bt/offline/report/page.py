"""The report as one self-contained HTML page: summary, field reliability, trends,
funnel, engagement, causes, provenance, plots and a table of the tours.

Everything the page shows is escaped text written here; its one small script only
sorts, filters and opens rows, reading cells' text and ``data-`` attributes
(``textContent``, ``dataset``): no data goes through ``innerHTML``, nothing is fetched.
"""

from __future__ import annotations

import html
import json
from typing import Any

from frog_bt.offline.report import headline
from frog_bt.offline.report.headline import rate
from frog_bt.offline.report.intervals import TOO_FEW, Estimate, proportion, wilson
from frog_bt.offline.report.precision import estimate, measure, places, signed
from frog_bt.offline.report.rows import Row

e = html.escape

# Published figures of long deployments, beside ours (docs/REPORT.md gives the sources).
PUBLISHED = [
    ("RoboX at Expo.02", "1.9 km per robot-day", "11 robots, 159 days"),
    ("STRANDS", "1.1 km per robot-day", "30 days autonomous"),
    ("Mobot", "2,500 robot-days", "help only occasional, and requested explicitly"),
]


DASH = "\u2013"


def _table(rows: list[tuple[str, str]], ident: str) -> str:
    body = "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in rows)
    return f'<table class="kv" id="{ident}">{body}</table>'


def _grid(head: list[str], rows: list[list[str]], ident: str) -> str:
    h = "".join(f"<th>{e(c)}</th>" for c in head)
    b = "".join("<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f'<table class="grid" id="{ident}"><tr>{h}</tr>{b}</table>'


def _figures(figures: list[headline.Figure], ident: str) -> str:
    return _table([(f.label, f.shown) for f in figures], ident)


def summary(t: dict[str, Any]) -> str:
    return _figures(headline.summary(t), "summary")


def reliability(rel: dict[str, Any], tours: int) -> str:
    published = _grid(
        ["deployment", "figure", "note"],
        [list(p) for p in PUBLISHED],
        "published",
    )
    return (
        _figures(headline.reliability(rel, tours), "reliability")
        + f'<p class="note">{e(headline.IN_SERVICE)}</p>'
        + "<p>Published figures of long deployments:</p>"
        + published
    )


def per_day(t: dict[str, Any], rel: dict[str, Any] | None) -> str:
    head = ["day", "tours", "completion", "part b (all stops' visits)", "interventions"]
    if rel is not None:
        head += ["hours in service", "autonomy", "km"]
    rows = []
    for day, d in t["per_day"].items():
        row = [
            day,
            str(d["tours"]),
            rate(d["completion"]),
            rate(d["part_b"]),
            str(d["interventions"]),
        ]
        r = (rel or {}).get("per_day", {}).get(day)
        if rel is not None:
            row += (
                [
                    measure(r["hours_in_service"]),
                    next(
                        f.shown
                        for f in headline.reliability(r, d["tours"])
                        if "Autonomy" in f.label
                    ),
                    measure(r["km_per_robot_day"] or 0.0),
                ]
                if r
                else ["\u2013"] * 3
            )
        rows.append(row)
    return _grid(head, rows, "per-day")


def funnel(t: dict[str, Any]) -> str:
    f = t["funnel"]
    start = f.get("started") or 0
    return _grid(
        ["", *f],
        [
            ["visitors", *(str(n) for n in f.values())],
            [
                "share",
                *(
                    estimate(proportion(wilson(n, start)), " %") if start else "\u2013"
                    for n in f.values()
                ),
            ],
        ],
        "funnel",
    )


def engagement(t: dict[str, Any]) -> str:
    rows = []
    for by, label in (
        ("by_stop", "stop"),
        ("by_hour", "hour (all stops)"),
        ("by_variant", "variant"),
    ):
        for key, r in t["engagement"][by].items():
            rows.append([label, f"{key}:00" if by == "by_hour" else key, rate(r)])
    return _grid(["by", "", "part b played (95 % interval)"], rows, "engagement") + (
        "<p>Pooled figures count each visit (a visitor's stops are not independent "
        "trials, so their intervals are narrower than they should be).</p>"
    )


def causes(t: dict[str, Any]) -> str:
    rows = [
        [c["cause"], c["detail"], str(c["events"]), str(c["tours"])] for c in t["failure_causes"]
    ]
    return _grid(["cause", "detail", "events", "tours"], rows or [["none", "", "", ""]], "causes")


def _when(iso: str | None) -> str:
    """``2026-06-01T09:06:26+02:00`` as a reader writes it: ``2026-06-01 09:06:26``."""
    return "\u2013" if not iso else iso[:19].replace("T", " ")


def provenance(p: dict[str, Any]) -> str:
    lines = [
        (
            "Recordings",
            f"{p['files']} files read ({len(p['cut_short'])} of them cut short), "
            f"{len(p['skipped'])} skipped",
        ),
        (
            "Runs",
            f"{p['runs']} runs"
            + (
                f"; {p['without_run_id']} files recorded before run ids "
                "(a copy among them is found by its time alone)"
                if p["without_run_id"]
                else ""
            ),
        ),
        ("From (local time)", _when(p["first"])),
        ("To (local time)", _when(p["last"])),
        ("Written by", ", ".join(f"{k} ({n} files)" for k, n in p["versions"].items()) or "\u2013"),
        (
            "Trees (sha256)",
            ", ".join(f"{k} ({n} files)" for k, n in p["trees"].items()) or "\u2013",
        ),
        (
            "Site configurations (sha256)",
            ", ".join(f"{k} ({n} files)" for k, n in p["configs"].items()) or "\u2013",
        ),
    ]
    skipped = "".join(f"<li>skipped: {e(s)}</li>" for s in p["skipped"])
    doubtful = "".join(f"<li>suspicious: {e(s)}</li>" for s in p["suspicious"])
    cut = "".join(f"<li>read in part: {e(s)}</li>" for s in p["cut_short"])
    listed = skipped + doubtful + cut
    return _table(lines, "provenance") + (f'<ul class="skip">{listed}</ul>' if listed else "")


def _moved(d: dict[str, Any]) -> tuple[str, str, str]:
    """B - A, its interval, whether it differs: to the difference's precision (a measured
    total's: to that of the two figures)."""
    if d["difference"] is None:
        return DASH, DASH, DASH
    unit = " points" if d["unit"] == " %" else d["unit"]
    if d["low"] is None:
        p = max(places(d["a"]), places(d["b"]))
        why = "measured: none" if d["how"] == "measured" else TOO_FEW
        return signed(d["difference"], p, unit), why, DASH
    moved_by: Estimate = {
        "value": d["difference"],
        "low": d["low"],
        "high": d["high"],
        "how": d["how"],
    }
    p = places(moved_by)
    low, high = signed(d["low"], p), signed(d["high"], p)
    return signed(d["difference"], p, unit), f"{low} to {high}", "yes" if d["significant"] else "no"


def compare(c: dict[str, Any]) -> str:
    rows = [
        [d["label"], d["shown"][0] or DASH, d["shown"][1] or DASH, *_moved(d)] for d in c["figures"]
    ]
    skipped = "".join(f"<li>{e(s)}</li>" for s in c["skipped_b"])
    return (
        f"<p>{e(c['a'])} (A) beside {e(c['b'])} (B): every figure of the summary and the "
        "field reliability, as each season's page shows it, and the difference B \u2212 A "
        "with its 95 % interval (MOVER, from the two figures' intervals: Newcombe's hybrid "
        "score for two rates, in percentage points); it differs when that interval leaves "
        "0 out. Counts and totals measured whole (tours, visitors, hours in service, km) "
        "have no sampling interval.</p>"
        + _grid(["figure", "A", "B", "B \u2212 A", "95 % interval", "differs"], rows, "compare")
        + (f'<p>Skipped in B:</p><ul class="skip">{skipped}</ul>' if skipped else "")
    )


COLUMNS = [  # (header, key for sorting, kind)
    ("#", "tour", "n"),
    ("Day", "day", "s"),
    ("Start", "start", "s"),
    ("Min", "min", "n"),
    ("Metres", "m", "n"),
    ("Visitors", "visitors", "n"),
    ("Stops", "stops", "n"),
    ("Part b", "b", "n"),
    ("Skipped", "skipped", "s"),
    ("Ending", "ending", "s"),
    ("Incidents", "incidents", "s"),
]


def _tour(r: Row, order: list[str]) -> str:
    ending = r.ended if r.ended != "aborted" else f"aborted: {r.reason}"
    incidents: dict[str, int] = {}
    for i in r.incidents:
        incidents[str(i)] = incidents.get(str(i), 0) + 1
    said = ", ".join(k if n == 1 else f"{k} \u00d7{n}" for k, n in incidents.items())
    reached = len({p for p in r.stops_reached if p in order})
    skipped = ", ".join(f"{s.poi} ({s.why})" for s in r.stops_skipped)
    cells = [
        (str(r.tour), str(r.tour)),
        (r.day.isoformat(), r.day.isoformat()),
        (r.start.strftime("%H:%M"), r.start.isoformat()),
        (f"{r.duration_s / 60:.1f}", str(r.duration_s)),
        (f"{r.distance_m:.0f}", str(r.distance_m)),
        (str(r.visitors), str(r.visitors)),
        (f"{reached} of {len(order)}", str(reached)),
        (
            " ".join(v.poi for v in r.engagement if v.decision == "b") or "\u2013",
            str(sum(v.decision == "b" for v in r.engagement)),
        ),
        (skipped, skipped),
        (ending, r.ended),
        (said, said),
    ]
    tds = "".join(
        f'<td data-v="{e(v)}"{" title=" + chr(34) + e(text) + chr(34) if len(text) > 30 else ""}>'
        f"{e(text)}</td>"
        for text, v in cells
    )
    more = [
        ("Files", ", ".join(r.files)),
        ("Stops reached", " → ".join(r.stops_reached) or "none"),
        ("Stops played", " → ".join(r.stops_played) or "none"),
        ("Parts", ", ".join(str(p) for p in r.parts) or "none"),
        ("Engagement", ", ".join(str(v) for v in r.engagement) or "none"),
        (
            "Approaches",
            f"{r.approaches} ({r.approaches_rejected} rejected); invitations {r.invitations} "
            f"({r.invitations_declined} declined); introduction {r.introduction}",
        ),
        ("Time at stops", ", ".join(str(s) for s in r.time_at_stops) or "none"),
        ("Faults", "; ".join(r.faults) or "none"),
        (
            "Operator",
            "; ".join(f"+{c.at_s:g} s {c}{' by ' + c.by if c.by else ''}" for c in r.operator)
            or "none",
        ),
        (
            "Alerts",
            "; ".join(
                f"+{a.raised_s:g} s {a.kind} ({a.severity})"
                + (
                    ""
                    if a.acknowledged_s is None
                    else f", acknowledged after {a.acknowledged_s:g} s"
                )
                + (f" by {a.acknowledged_by}" if a.acknowledged_by else "")
                + ("" if a.cleared_s is None else f", cleared after {a.cleared_s:g} s")
                for a in r.alerts
            )
            or "none",
        ),
        ("Incidents", said or "none"),
    ]
    details = "".join(f"<dt>{e(k)}</dt><dd>{e(v)}</dd>" for k, v in more)
    stops = " ".join(dict.fromkeys(r.stops_reached))
    return (
        f'<tbody data-day="{e(r.day.isoformat())}" data-ending="{e(r.ended)}" '
        f'data-stops="{e(stops)}"><tr class="row">{tds}</tr>'
        f'<tr class="more" hidden><td colspan="{len(COLUMNS)}"><dl>{details}</dl></td></tr></tbody>'
    )


SCRIPT = """
(function () {
  var table = document.getElementById('tours');
  var bodies = function () { return Array.prototype.slice.call(table.tBodies); };
  var pick = { ending: document.getElementById('f-ending'), day: document.getElementById('f-day'),
               stop: document.getElementById('f-stop') };
  var shown = document.getElementById('shown');
  function filter() {
    var n = 0;
    bodies().forEach(function (b) {
      var ok = (!pick.ending.value || b.dataset.ending === pick.ending.value) &&
               (!pick.day.value || b.dataset.day === pick.day.value) &&
               (!pick.stop.value || b.dataset.stops.split(' ').indexOf(pick.stop.value) >= 0);
      b.hidden = !ok; n += ok ? 1 : 0;
    });
    shown.textContent = n + ' of ' + bodies().length + ' tours';
  }
  Object.keys(pick).forEach(function (k) { pick[k].addEventListener('change', filter); });
  var heads = table.tHead.rows[0].cells;
  Array.prototype.forEach.call(heads, function (th, i) {
    th.addEventListener('click', function () {
      var up = th.dataset.dir !== 'up';
      Array.prototype.forEach.call(heads, function (h) { delete h.dataset.dir; });
      th.dataset.dir = up ? 'up' : 'down';
      var num = th.dataset.kind === 'n';
      var list = bodies();
      list.sort(function (a, b) {
        var x = a.rows[0].cells[i].dataset.v, y = b.rows[0].cells[i].dataset.v;
        var c = num ? (parseFloat(x) || 0) - (parseFloat(y) || 0) : x.localeCompare(y);
        return up ? c : -c;
      });
      list.forEach(function (b) { table.appendChild(b); });
    });
  });
  bodies().forEach(function (b) {
    b.rows[0].addEventListener('click', function () { b.rows[1].hidden = !b.rows[1].hidden; });
  });
  filter();
})();
"""

STYLE = """
body { font: 15px/1.45 system-ui, sans-serif; margin: 1.5em auto; max-width: 82em;
       padding: 0 1em; color: #1d2733; }
h1 { font-size: 1.6em; } h2 { font-size: 1.2em; margin-top: 1.8em; }
table { border-collapse: collapse; } td, th { padding: .2em .6em; text-align: left;
        border-bottom: 1px solid #dde3ea; vertical-align: top; }
.kv th { font-weight: 600; white-space: nowrap; }
.grid th { background: #eef2f6; } .grid td:first-child, #funnel td { white-space: nowrap; }
.cols { display: flex; flex-wrap: wrap; gap: 0 2.5em; } .cols > div { flex: 1 1 30em; }
.figs { display: flex; flex-wrap: wrap; gap: 1em; }
figure { margin: 0; } figcaption { font-weight: 600; } img { max-width: 100%; }
#tours { width: 100%; table-layout: fixed; font-size: .86em; }
#tours thead th { cursor: pointer; background: #eef2f6; position: sticky; top: 0;
                  white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }
#tours th[data-dir=up]::after { content: " ▲"; } #tours th[data-dir=down]::after { content: " ▼"; }
#tours tr.row td { white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }
#tours tr.row { cursor: pointer; } #tours tr.row:hover { background: #f4f7fa; }
#tours tr.more td { background: #f8fafc; white-space: normal; }
#tours dl { display: grid; grid-template-columns: 9em 1fr; margin: .3em 0; gap: .1em 1em; }
#tours dt { font-weight: 600; } #tours dd { margin: 0; }
.filters { margin: .5em 0; } .filters label { margin-right: 1.2em; }
.skip { color: #8a4b00; }
"""

# Each column as wide as its header with the sort arrow (" ▲") and its usual cells
# ("2026-06-01", "6 of 6", "POI3 (operator)", "aborted: operator"); Incidents, the widest
# and what a reader looks for, takes the rest. Longer cells end in "…" (their title has
# them whole) and the tour's details have everything.
WIDTHS = [
    "3.2em",
    "7.2em",
    "5.3em",
    "4.5em",
    "6.4em",
    "6.8em",
    "5.7em",
    "7.5em",
    "9.2em",
    "10.2em",
    "",
]


def page(
    rows: list[Row],
    t: dict[str, Any],
    figures: list[tuple[str, str]],
    title: str,
    skipped: list[str],
    extra: str = "",
) -> str:
    order = list(t["funnel"])[1:-1]
    rel = t.get("reliability")
    cols = "".join(f'<col style="width:{w}">' if w else "<col>" for w in WIDTHS)
    head = "".join(f'<th data-kind="{k}" title="sort by {e(h)}">{e(h)}</th>' for h, _, k in COLUMNS)

    def options(ident: str, label: str, values: list[str]) -> str:
        opts = "".join(f'<option value="{e(v)}">{e(v)}</option>' for v in values)
        return (
            f'<label>{e(label)} <select id="{ident}">'
            f'<option value="">all</option>{opts}</select></label>'
        )

    filters = (
        options("f-ending", "Ending", sorted({r.ended for r in rows}))
        + options("f-day", "Day", sorted({r.day.isoformat() for r in rows}))
        + options("f-stop", "Stop visited", order)
        + '<span id="shown"></span>'
    )
    data = json.dumps(t).replace("</", "<\\/")  # raw text inside <script>: no entities
    sections = [
        "<h2>Summary</h2>" + summary(t),
        *(["<h2>Field reliability</h2>" + reliability(rel, t["tours"])] if rel else []),
    ]
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{e(title)}</title>
<style>{STYLE}</style></head><body>
<h1>{e(title)}</h1>
<div class="cols">{"".join(f"<div>{s}</div>" for s in sections)}</div>
{"<h2>Compared: A beside B</h2>" + compare(t["compare"]) if "compare" in t else ""}
{extra}
<h2>Per day</h2>{per_day(t, rel)}
<div class="cols"><div><h2>Stop by stop: where visitors drop out</h2>{funnel(t)}
<h2>Engagement: part b played</h2>{engagement(t)}</div>
<div><h2>Failure causes (each event once)</h2>{causes(t)}</div></div>
<h2>Plots</h2>
<div class="figs">{
        "".join(
            f'<figure><figcaption>{e(name)}</figcaption><img alt="{e(name)}" src="{url}"></figure>'
            for name, url in figures
        )
    }</div>
<h2>Tours</h2>
<p>One line per tour, local times; click a header to sort, a tour for its details.</p>
<div class="filters">{filters}</div>
<table id="tours"><colgroup>{cols}</colgroup><thead><tr>{head}</tr></thead>
{"".join(_tour(r, order) for r in rows)}</table>
{
        "<h2>Provenance</h2>" + provenance(t["provenance"])
        if "provenance" in t
        else "".join(f'<p class="skip">skipped: {e(s)}</p>' for s in skipped)
    }
<script type="application/json" id="totals">{data}</script>
<script>{SCRIPT}</script>
</body></html>
"""
