"""A whole simulated tour recorded with telemetry, read back with rerun's RrdReader."""

from __future__ import annotations

import itertools

from rerun.chunk import RrdReader
from telemetry_tour import Recorded

from frog_bt.clock import SITE_TZ
from frog_bt.live.telemetry.layout import TIME
from frog_bt.live.telemetry.writer import TRAIL_EVERY


def test_the_tour_itself_went_fine(recorded: Recorded):
    assert recorded.outcome.code == 0, recorded.outcome.reason
    assert recorded.telemetry.rows.core is None  # close() took the taps off the core
    assert recorded.telemetry.write_errors == 0


def test_robot_pose_rows_cover_the_tour(recorded: Recorded):
    poses = recorded.rows("/map/robot")
    assert poses > 500  # /FROG_pose at 10 Hz for minutes of sim time
    assert recorded.rows("/map/robot/heading") == poses
    assert recorded.rows("/map/robot/trail") >= poses // TRAIL_EVERY
    positions = recorded.values("/map/robot", "Points2D:positions")
    xs = [p[0][0] for p in positions]
    ys = [p[0][1] for p in positions]
    # the tour reaches from the shop (y 17) to the Vault Room (y 141)
    assert min(ys) < 25 and max(ys) > 130 and max(xs) - min(xs) > 50


def test_every_node_has_a_status_lane_and_several_ran_and_succeeded(recorded: Recorded):
    index = recorded.telemetry.index
    lanes = {
        n.key: [
            s for row in recorded.values(f"/bt/status/{n.key}", "StateChange:state") for s in row
        ]
        for n in index.nodes
    }
    assert all(f"/bt/status/{key}" in recorded.chunks for key in lanes)
    ran = [key for key, states in lanes.items() if "RUNNING" in states]
    succeeded = [key for key, states in lanes.items() if "SUCCESS" in states]
    assert len(ran) > 10 and len(succeeded) > 10
    navigate = next(k for k in lanes if k.endswith("_Navigate_POI0"))
    assert lanes[navigate][:3] == ["INVALID", "RUNNING", "SUCCESS"]
    for states in lanes.values():  # logged on change only
        assert all(a != b for a, b in itertools.pairwise(states))


def test_graph_is_static_with_temporal_colours(recorded: Recorded):
    n = len(recorded.telemetry.index)
    ids = recorded.values("/bt/graph", "GraphNodes:node_ids", static=True)
    assert [len(row) for row in ids] == [n]
    positions = recorded.values("/bt/graph", "GraphNodes:positions", static=True)[0]
    assert len(positions) == n
    edges = recorded.values("/bt/graph", "GraphEdges:edges", static=True)[0]
    assert len(edges) == n - 1
    colours = recorded.values("/bt/graph", "GraphNodes:colors")
    assert len(colours) > 10 and all(len(row) == n for row in colours)
    assert recorded.values("/bt/graph", "GraphNodes:colors", static=True) == []


def test_text_log_has_commands_events_and_decisions(recorded: Recorded):
    ros = recorded.texts("/log/ros/out")
    assert "→ robot /docking/dock undock" in ros
    assert any(t.startswith("→ robot /GotoWayPoint POI0 (") for t in ros)
    assert "→ robot /ApproachPeopleFar 7" in ros
    frontend = recorded.texts("/log/frontend/out")
    assert "→ front end tour state=started" in frontend
    assert "→ front end tour state=ended" in frontend
    assert "← front end frontend_idle" in recorded.texts("/log/frontend/in")
    assert "← robot /FROG_response 2 (succeeded)" in recorded.texts("/log/ros/in")
    notes = recorded.texts("/log/notes")
    assert "arrived at POI0" in notes and "approach visitor 7" in notes


def test_map_scene_and_series(recorded: Recorded):
    labels = [
        label
        for row in recorded.values("/map/pois", "Points2D:labels", static=True)
        for label in row
    ]
    assert "POI0" in labels and "POI1a/POI1b" in labels and "SHOP" in labels
    assert recorded.values("/map/route", "LineStrips2D:strips", static=True)
    assert recorded.rows("/map/visitors") > 10
    assert "7" in [
        label for row in recorded.values("/map/visitors", "Points2D:labels") for label in row
    ]
    assert recorded.rows("/plots/battery") > 10
    assert recorded.rows("/plots/people/persons") > 10
    assert recorded.rows("/plots/engagement/faces/7") > 10  # the face stream at stops
    goals = recorded.values("/map/goal", "Points2D:labels")
    assert ["goal POI0"] in goals


def test_blueprint_is_in_the_file(recorded: Recorded):
    reader = RrdReader(recorded.path)
    [blueprint] = reader.blueprints()
    views = {}
    for chunk in reader.stream(store=blueprint):
        batch = chunk.to_record_batch()
        if "ViewBlueprint:class_identifier" in batch.schema.names:
            kind = batch.column("ViewBlueprint:class_identifier").to_pylist()[0][0]
            name = batch.column("ViewBlueprint:display_name").to_pylist()[0][0]
            views[name] = kind
    assert views["Map"] == "2D"
    assert views["Running path"] == "Graph"
    assert views["Whole tree"] == "Graph"
    assert views["Stops"] == "StateTimeline"
    assert views["Bookmarks"] == "TextLog"
    assert views["Tour phases"] == "StateTimeline"
    assert views["All nodes"] == "StateTimeline"
    assert views["Log"] == "TextLog"
    assert views["Engagement"] == "TimeSeries"


def test_the_running_path_is_a_small_graph_from_the_root(recorded: Recorded):
    rows = recorded.values("/bt/path", "GraphNodes:node_ids")
    assert len(rows) > 10
    whole = recorded.values("/bt/graph", "GraphNodes:node_ids", static=True)[0]
    for ids in rows:
        assert ids[0] == whole[0]  # the root first
        assert 1 < len(ids) < len(whole) // 2  # a path with its siblings, not the tree
    assert len({tuple(ids) for ids in rows}) > 3  # it follows the tour


def test_the_running_paths_edges_join_each_shown_node_to_its_parent(recorded: Recorded):
    tree = recorded.values("/bt/graph", "GraphEdges:edges", static=True)[0]
    parent = {pair["second"]: pair["first"] for pair in tree}
    ids = recorded.values("/bt/path", "GraphNodes:node_ids")
    edges = recorded.values("/bt/path", "GraphEdges:edges")
    assert len(edges) == len(ids) > 10  # logged together, whenever the path changes
    for shown, pairs in zip(ids, edges, strict=True):
        assert len(pairs) == len(shown) - 1
        assert {(p["first"], p["second"]) for p in pairs} == {(parent[n], n) for n in shown[1:]}


def test_each_stop_has_a_lane_reached_then_played(recorded: Recorded):
    lane = [s[0] for s in recorded.values("/stops/POI1", "StateChange:state")]
    assert lane[:2] == ["reached", "played"]


def test_the_tours_clock_starts_with_the_tour_not_in_1970(recorded: Recorded):
    # rows logged before sim time had a /clock (the links, connecting) carry the tick only;
    # the timeline reads as the site's clocks do: the scenario starts at 10:30 in Madrid
    import datetime

    from frog_bt.sim.scenario import DEFAULT_START

    tour_day = datetime.datetime(2026, 1, 1)
    stamps = [
        stamp
        for chunks in recorded.chunks.values()
        for chunk in chunks
        if not chunk.is_static
        for batch in [chunk.to_record_batch()]
        if TIME in batch.schema.names
        for stamp in batch.column(TIME).to_pylist()
        if stamp is not None
    ]
    assert stamps and min(stamps).replace(tzinfo=None) >= tour_day
    start = DEFAULT_START.astimezone(SITE_TZ).replace(tzinfo=None)
    first = min(stamps).replace(tzinfo=None)
    assert start <= first < start + datetime.timedelta(minutes=5)
