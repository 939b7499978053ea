"""The default viewer layout sent with every recording (imports rerun; loaded lazily).

The tree gets the whole width: it is wide (one column per leaf), and a
narrower view makes its labels too small to read without zooming::

    ┌──────────────────────────────────────────────────────────────────────┐
    │ Behaviour tree: the graph, node colours following their status       │
    ├───────────────────┬──────────────────────────────┬───────────────────┤
    │ Map: POIs, route, │ Status lanes: tour phases |  │ Log: decisions,   │
    │ zones, robot and  │ all nodes (tabs)             │ commands, events  │
    │ trail, visitors,  ├──────────────────────────────┤                   │
    │ goal              │ Engagement | People | Battery│                   │
    └───────────────────┴──────────────────────────────┴───────────────────┘
"""

from __future__ import annotations

import rerun as rr
import rerun.blueprint as rrb

from frog_bt.live.telemetry.layout import TreeIndex
from frog_bt.live.telemetry.writer import TICK, TIME, status_path

# Status lanes show the whole run up to the time cursor.
SO_FAR = rrb.archetypes.TimeAxis(
    view_range=rr.TimeRange(
        start=rr.TimeRangeBoundary.infinite(), end=rr.TimeRangeBoundary.cursor_relative(seq=0)
    )
)


def default_blueprint(index: TreeIndex) -> rrb.Blueprint:
    phases = [f"+ /{status_path(index.nodes[i].key)}" for i in index.phases()]
    lanes = rrb.Tabs(
        rrb.StateTimelineView(
            name="Tour phases", origin="/bt/status", contents=phases, time_view=SO_FAR
        ),
        rrb.StateTimelineView(name="All nodes", origin="/bt/status", time_view=SO_FAR),
    )
    plots = rrb.Horizontal(
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
    bottom = rrb.Horizontal(
        rrb.Spatial2DView(name="Map", origin="/", contents=["+ /map/**"]),
        rrb.Vertical(
            lanes,
            rrb.StateTimelineView(name="Links", origin="/links", time_view=SO_FAR),
            plots,
            row_shares=[5, 3, 4],
        ),
        rrb.TextLogView(
            name="Log",
            origin="/log",
            columns=rrb.archetypes.TextLogColumns(
                # the viewer cuts time columns to "#..." this narrow; a row click sets the cursor
                timeline_columns=[
                    rrb.components.TimelineColumn(TIME, visible=False),
                    rrb.components.TimelineColumn(TICK, visible=False),
                ],
                text_log_columns=[
                    rrb.components.TextLogColumn("loglevel"),
                    rrb.components.TextLogColumn("body"),
                    rrb.components.TextLogColumn("entitypath", visible=False),
                ],
            ),
            rows=rrb.archetypes.TextLogRows(filter_by_log_level=["INFO", "WARN", "ERROR"]),
        ),
        column_shares=[7, 7, 6],
    )
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.GraphView(name="Behaviour tree", origin="/bt/graph"), bottom, row_shares=[1, 2]
        ),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed", timeline=TICK, play_state="following"),
    )
