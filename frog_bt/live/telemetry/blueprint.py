"""The default viewer layout sent with every recording (imports rerun; loaded lazily).

The tree opens on its running path (the root down to the running leaf, with the
siblings of each node on it: a few dozen nodes, legible at 1,400 px); the whole
tree is the next tab. The time panel runs on the tour's own clock (``time``)::

    ┌─────────────────────────────────────────┬────────────────────────────┐
    │ Running path | Whole tree (tabs)        │ Map: POIs, route, zones,   │
    │                                         │ robot, trail, visitors     │
    ├─────────────────────────────────────────┼────────────────────────────┤
    │ Stops | Tour phases | All nodes | Links │ Log | Bookmarks (tabs):    │
    ├─────────────────────────────────────────┤ time, level, text          │
    │ Engagement | People seen | Battery %    │                            │
    └─────────────────────────────────────────┴────────────────────────────┘
    time panel: the `time` timeline, bookmarks (staff, doubted, faults, reload) as rows
"""

from __future__ import annotations

import rerun as rr
import rerun.blueprint as rrb

from frog_bt.live.telemetry.layout import TICK, TIME, TreeIndex, status_path

# Status lanes show the whole run up to the time cursor.
SO_FAR = rrb.archetypes.TimeAxis(
    view_range=rr.TimeRange(
        start=rr.TimeRangeBoundary.infinite(), end=rr.TimeRangeBoundary.cursor_relative(seq=0)
    )
)


def default_blueprint(
    index: TreeIndex, bt: str = "bt", stops: list[str] | None = None
) -> rrb.Blueprint:
    """The layout above for the tree logged under ``bt`` (``bt/tree2`` after a reload)."""
    phases = [f"+ /{status_path(index.nodes[i].key, bt)}" for i in index.phases()]
    tree = rrb.Tabs(
        rrb.GraphView(name="Running path", origin=f"/{bt}/path"),
        rrb.GraphView(name="Whole tree", origin=f"/{bt}/graph"),
        active_tab=0,
    )
    lanes = rrb.Tabs(
        rrb.StateTimelineView(name="Stops", origin="/stops", time_view=SO_FAR),
        rrb.StateTimelineView(
            name="Tour phases", origin=f"/{bt}/status", contents=phases, time_view=SO_FAR
        ),
        rrb.StateTimelineView(name="All nodes", origin=f"/{bt}/status", time_view=SO_FAR),
        rrb.StateTimelineView(name="Links", origin="/links", time_view=SO_FAR),
        active_tab=0,
    )
    plots = rrb.Tabs(
        *(
            rrb.TimeSeriesView(
                name=name,
                origin=origin,
                axis_x=SO_FAR,
                plot_legend=rrb.PlotLegend(corner="RightBottom"),
            )
            for name, origin in (
                ("Engagement", "/plots/engagement"),
                ("People seen", "/plots/people"),
                ("Battery %", "/plots/battery"),
            )
        )
    )
    log_columns = rrb.archetypes.TextLogColumns(
        timeline_columns=[
            rrb.components.TimelineColumn(TIME, visible=True),
            rrb.components.TimelineColumn(TICK, visible=False),
        ],
        text_log_columns=[
            rrb.components.TextLogColumn("loglevel"),
            rrb.components.TextLogColumn("body"),
            rrb.components.TextLogColumn("entitypath", visible=False),
        ],
    )
    logs = rrb.Tabs(
        rrb.TextLogView(
            name="Log",
            origin="/log",
            columns=log_columns,
            rows=rrb.archetypes.TextLogRows(filter_by_log_level=["INFO", "WARN", "ERROR"]),
        ),
        rrb.TextLogView(name="Bookmarks", origin="/log/bookmarks", columns=log_columns),
    )
    top = rrb.Horizontal(
        tree,
        rrb.Spatial2DView(name="Map", origin="/", contents=["+ /map/**"]),
        column_shares=[3, 2],
    )
    bottom = rrb.Horizontal(
        rrb.Vertical(lanes, plots, row_shares=[3, 2]), logs, column_shares=[1, 1]
    )
    return rrb.Blueprint(
        rrb.Vertical(top, bottom, row_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        # the tour's own clock (sim or wall time), so that a time from the report or the
        # console's log finds the moment; the tick timeline is one click away
        rrb.TimePanel(state="expanded", timeline=TIME, play_state="following"),
    )
