"""Rows to rerun: the static scene once, then batches of rows as columns.

Imported only by :meth:`frog_bt.live.telemetry.Telemetry.open` (it imports rerun).
Every call goes through the one :class:`rerun.RecordingStream` it is given;
frequent rows (poses, statuses, detections, samples, scalars, text) are sent
with ``send_columns`` on both timelines, rare ones (the goal) with ``log``.
Entity paths are listed in ``docs/TELEMETRY.md``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import py_trees
import rerun as rr

from frog_bt.config import Site
from frog_bt.live.telemetry.layout import (
    TICK,
    TIME,
    TreeIndex,
    site_ns,
    site_offset,
    status_path,
    tidy_layout,
)
from frog_bt.live.telemetry.rows import CODES, STATES, Batch
from frog_bt.live.telemetry.site_map import poi_marks, tour_routes, zone_outlines
from frog_bt.model.frontend import message_fields
from frog_bt.model.links import Health, LinkStatus
from frog_bt.model.outcomes import DockingState
from frog_bt.model.ros import Pose
from frog_bt.model.wire import ABORTED, FAILED, Response

if TYPE_CHECKING:
    from frog_bt.model.events import RobotCommand

Status = py_trees.common.Status

STATUS_COLORS = {
    Status.RUNNING: 0xF5B400FF,
    Status.SUCCESS: 0x2EA043FF,
    Status.FAILURE: 0xE5484DFF,
    Status.INVALID: 0x8B949EFF,
}
COLOR_TABLE = np.array([STATUS_COLORS[s] for s in CODES], dtype=np.uint32)  # code -> colour
ROUTE_COLORS = (0xA371F7AA, 0x39C5CFAA, 0xDB61A2AA, 0x8B949EAA)  # one per period of the day
ZONE_COLORS = {"volume": 0x3FB95099, "special": 0xDB61A299}
FACING, NOT_FACING, TRACKED = 0x3FB950FF, 0xFF8C42FF, 0x8B949E66
ROBOT, TRAIL, GOAL, POI, FACE = 0x58A6FFFF, 0xF5B400DD, 0xF778BAFF, 0xE6EDF3FF, 0x8B949EFF
# Negative radii are UI points: markers stay visible however far the map is zoomed out.
R_ROBOT, R_POI, R_VISITOR, R_TRACKED, R_GOAL = -7.0, -4.0, -5.0, -9.0, -6.0
R_ROUTE, R_TRAIL, R_ZONE, R_ARROW = -1.5, -2.0, -1.0, -1.5
PERIODIC = frozenset({"engagement"})  # front-end commands sent on a timer: DEBUG, not INFO
TRAIL_STEP = 0.5  # metres between trail points
TRAIL_POINTS = 1000  # the trail keeps the last 500 m or so
TRAIL_EVERY = 40  # poses between two logged trails (4 s at 10 Hz; the trail is most of a file)
PATH_CHAR, PATH_GAP, PATH_LEVEL = 7.5, 24.0, 60.0  # the running path's layout (graph units)
LANES_PER_STEP = 4  # status lanes written per step of a batch
STATUSES_PER_STEP = 2000  # node statuses (rows x nodes) read per step of a batch
Goal = tuple[str, float, float, float]  # waypoint, x, y, yaw
GoalRow = tuple[int, int, float, Goal | None]  # tick, 0 input / 1 output, t, goal or cleared


def tree_root(generation: int) -> str:
    """The entity under which a tree is logged: ``bt``, then ``bt/tree2``, ``bt/tree3``."""
    return "bt" if generation == 1 else f"bt/tree{generation}"


STOP_STATES = ("to come", "reached", "played", "skipped")
STOP_COLORS = np.array([0x8B949EFF, 0x58A6FFFF, 0x2EA043FF, 0xE5484DFF], dtype=np.uint32)
MARK_PATHS = {"staff": "log/bookmarks/staff", "doubted": "log/bookmarks/doubted"}
MARK_PATHS["fault"] = "log/bookmarks/faults"
RELOAD_PATH = "log/bookmarks/reload"


HEALTH_COLORS = {
    Health.OK: 0x3CB371FF,
    Health.WAIT: 0xE0A030FF,
    Health.BAD: 0xD04040FF,
    Health.OFF: 0x808080FF,
}  # the colour of a link lane, by its state's health


def link_path(name: str) -> str:
    return f"links/{name}"


def _times(rows: Sequence[tuple[Any, ...]]) -> list[rr.TimeColumn]:
    # Nanoseconds as rerun rounds them one by one (round(1e9 * t)), but in one numpy pass:
    # a list of floats costs rerun a Python conversion per row. On the site's clock
    # (layout.site_offset): one offset for the batch, unless summer time began or ended.
    t = np.array([r[1] for r in rows], dtype=np.float64)
    first, last = site_offset(t[0]), site_offset(t[-1])
    shift = first if first == last else np.array([site_offset(x) for x in t])
    ns = np.round((t + shift) * 1e9).astype(np.int64)
    return [
        rr.TimeColumn(TICK, sequence=[r[0] for r in rows]),
        rr.TimeColumn(TIME, timestamp=ns.astype("datetime64[ns]")),
    ]


@dataclass(frozen=True, slots=True)
class _PathLayout:
    """One running path's graph, as the viewer gets it (see ``Writer._write_paths``)."""

    ids: list[str]
    labels: list[str]
    positions: list[tuple[float, float]]
    edges: list[tuple[str, str]]


class Writer:
    """Writes the static scene and then :class:`~frog_bt.live.telemetry.rows.Batch` es."""

    def __init__(self, rec: rr.RecordingStream, site: Site, index: TreeIndex) -> None:
        self.rec = rec
        self.site = site
        self.index = index
        self.topics = {site.topic(role): role for role in ("goto", "approach", "icl", "dock")}
        self.facing = (site.recruit.facing_min, site.recruit.facing_max)
        self._codes = np.full(len(index), CODES[Status.INVALID], dtype=np.uint8)  # now
        self.bt = "bt"  # the tree's root entity (a reload logs the next tree beside it)
        self._path: tuple[int, ...] = ()  # the nodes of the running-path view, as last logged
        self._shown = np.empty(0, dtype=np.uint8)  # and their status codes
        self._layouts: dict[tuple[int, ...], _PathLayout] = {}  # per path (one per leaf)
        self.stops = [stop.poi for stop in site.tour.stops]
        self._target: str | None = None  # the POI being driven to (blackboard /target)
        self._stop_state: dict[str, str] = {}
        self._trail: deque[tuple[float, float]] = deque(maxlen=TRAIL_POINTS)
        self._poses_since_trail = 0
        self._docking: str | None = None
        self._faults: tuple[str, ...] = ()
        self._goal: Goal | None = None
        self._faces: set[int] = set()

    # ------------------------------------------------------------ static

    def write_static(self) -> None:
        from frog_bt.live.telemetry.blueprint import default_blueprint

        rec, site = self.rec, self.site
        rec.send_blueprint(
            default_blueprint(self.index, self.bt, self.stops), make_active=True, make_default=True
        )
        stop_config = rr.StateConfiguration(values=list(STOP_STATES), colors=STOP_COLORS)
        for poi in dict.fromkeys(self.stops):
            rec.log(f"stops/{poi}", stop_config, static=True)
        rec.log("map", rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)  # map y points up
        marks = poi_marks(site)
        rec.log(
            "map/pois",
            rr.Points2D(
                [(m.x, m.y) for m in marks],
                radii=R_POI,
                colors=POI,
                labels=[m.label for m in marks],
                show_labels=True,
                draw_order=30,
            ),
            static=True,
        )
        heads = [(m.x, m.y, h) for m in marks for h in m.headings]
        rec.log(
            "map/pois/headings",
            rr.Arrows2D(
                origins=[(x, y) for x, y, _ in heads],
                vectors=[(3 * math.cos(h), 3 * math.sin(h)) for _, _, h in heads],
                radii=R_ARROW,
                colors=POI,
                draw_order=29,
            ),
            static=True,
        )
        routes = tour_routes(site)
        rec.log(
            "map/route",
            rr.LineStrips2D(
                [r.points for r in routes],
                radii=R_ROUTE,
                labels=[r.label for r in routes],
                colors=np.array(
                    [ROUTE_COLORS[i % len(ROUTE_COLORS)] for i in range(len(routes))],
                    dtype=np.uint32,
                ),
                show_labels=False,
                draw_order=10,
            ),
            static=True,
        )
        zones = zone_outlines(site)
        if zones:
            rec.log(
                "map/zones",
                rr.LineStrips2D(
                    [z.points for z in zones],
                    radii=R_ZONE,
                    labels=[z.label for z in zones],
                    colors=np.array(
                        [ZONE_COLORS.get(z.kind, 0x8B949E99) for z in zones], dtype=np.uint32
                    ),
                    show_labels=False,
                    draw_order=5,
                ),
                static=True,
            )
        rec.log(
            "map/robot",
            rr.Points2D.from_fields(
                radii=R_ROBOT, colors=ROBOT, labels="FROG", show_labels=False, draw_order=50
            ),
            static=True,
        )
        rec.log(
            "map/robot/heading",
            rr.Arrows2D.from_fields(radii=R_ARROW * 1.5, colors=ROBOT, draw_order=51),
            static=True,
        )
        rec.log(
            "map/robot/trail",
            rr.LineStrips2D.from_fields(radii=R_TRAIL, colors=TRAIL, draw_order=20),
            static=True,
        )
        rec.log(
            "map/people",
            rr.Points2D.from_fields(radii=R_TRACKED, colors=TRACKED, draw_order=39),
            static=True,
        )
        rec.log(
            "map/visitors",
            rr.Points2D.from_fields(radii=R_VISITOR, show_labels=True, draw_order=40),
            static=True,
        )
        self._write_tree()
        for name, color in (
            ("battery", 0x3FB950FF),
            ("persons", 0xFF8C42FF),
            ("people", 0x6E7681FF),
        ):
            path = "plots/battery" if name == "battery" else f"plots/people/{name}"
            rec.log(path, rr.SeriesLines(names=name, colors=color), static=True)
        rec.log(
            "plots/engagement/meter",
            rr.SeriesLines(names="meter", colors=0xFF8C42FF, widths=3.0),
            static=True,
        )
        rec.log(
            "plots/engagement/decision",
            rr.SeriesPoints(names="decision", colors=0xF778BAFF, marker_sizes=6.0),
            static=True,
        )

    def reload(self, tick: int, t: float, index: TreeIndex, generation: int) -> None:
        """Another tree runs from ``tick`` on (``run --watch``): logged beside the first
        (``bt/tree2``, ...), the default layout follows it, and the timeline marks it."""
        from frog_bt.live.telemetry.blueprint import default_blueprint

        self.index = index
        self.bt = tree_root(generation)
        self._codes = np.full(len(index), CODES[Status.INVALID], dtype=np.uint8)
        self._path = ()
        self._layouts = {}
        self._write_tree()
        self.rec.send_blueprint(
            default_blueprint(index, self.bt, self.stops), make_active=True, make_default=True
        )
        self._set_time(tick, t)
        self.rec.log(
            RELOAD_PATH,
            rr.TextLog(f"tree reloaded: {len(index)} nodes, now under /{self.bt}", level="WARN"),
        )

    def _write_tree(self) -> None:
        rec, nodes, bt = self.rec, self.index.nodes, self.bt
        ids = [n.key for n in nodes]
        rec.log(
            f"{bt}/graph",
            rr.GraphNodes(
                ids,
                positions=tidy_layout(self.index),
                labels=[n.name for n in nodes],
                show_labels=True,
            ),
            static=True,
        )  # colours are temporal: static ones would win
        rec.log(
            f"{bt}/graph",
            rr.GraphEdges([(ids[a], ids[b]) for a, b in self.index.edges()], graph_type="directed"),
            static=True,
        )
        config = rr.StateConfiguration(
            values=list(STATES),
            colors=np.array(
                [STATUS_COLORS[py_trees.common.Status[s]] for s in STATES], dtype=np.uint32
            ),
        )
        for node in nodes:
            rec.log(status_path(node.key, bt), config, static=True)
        links = rr.StateConfiguration(
            values=[s.value for s in LinkStatus],
            colors=np.array([HEALTH_COLORS[s.health] for s in LinkStatus], dtype=np.uint32),
        )
        for name in ("rosbridge", "frontend", "clock"):
            rec.log(link_path(name), links, static=True)

    def write_links(self, tick: int, t: float, changes: list[tuple[str, LinkStatus]]) -> None:
        """Links whose state changed at ``t``: their lanes, and one log line."""
        rec = self.rec
        rec.reset_time()
        rec.set_time(TICK, sequence=tick)
        if t > 0:  # before the clock has a time (sim time, no /clock yet): the tick only,
            # not 1970 on the tour's clock (the timeline would open on 56 years)
            rec.set_time(TIME, timestamp=np.datetime64(site_ns(t), "ns"))
        for name, state in changes:
            rec.log(link_path(name), rr.StateChange(state=state.value))
        level = "WARN" if any(s.health in (Health.WAIT, Health.BAD) for _, s in changes) else "INFO"
        rec.log("log/links", rr.TextLog(", ".join(f"{n} {s}" for n, s in changes), level=level))

    # ------------------------------------------------------------ batches

    def write(self, batch: Batch) -> None:
        for _ in self.steps(batch):
            pass

    def steps(self, batch: Batch) -> Iterator[None]:
        """:meth:`write` in steps of a few rerun calls each. A batch of a busy tree takes
        milliseconds to write; between two steps a caller on an event loop lets inputs
        through (see :meth:`frog_bt.live.telemetry.Telemetry.flush`)."""
        if batch.statuses:
            yield from self._write_statuses(batch.statuses)
        if batch.poses:
            yield from self._write_poses(batch.poses)
        logs: dict[str, list[tuple[int, float, str, str]]] = {}
        goals: list[GoalRow] = []
        yield from self._read_inputs(batch, logs, goals)
        self._read_outputs(batch, logs, goals)
        # inputs of a tick come before what it sends: order by (tick, input first, time)
        for tick, _, t, goal in sorted(goals, key=lambda g: g[:3]):
            if goal is not None or self._goal is not None:
                self._log_goal(tick, t, goal)
                yield
        for tick, t, _, message in batch.events:
            logs.setdefault("log/frontend/in", []).append(
                (tick, t, "INFO", "← front end " + _describe(message))
            )
        for tick, t, text, level in batch.notes:  # the level is the note's incident kind's
            logs.setdefault("log/notes", []).append((tick, t, level.value, text))
        self._read_blackboard(batch)
        self._write_stops(batch)
        for tick, t, kind, mark_level, text in batch.marks:
            logs.setdefault(MARK_PATHS[kind], []).append((tick, t, mark_level, text))
        for path, rows in logs.items():
            if not rows:  # an empty temporal chunk crashes the 0.41 viewer's time panel
                continue
            yield
            rows.sort(key=lambda r: (r[0], r[1]))
            self.rec.send_columns(
                path,
                indexes=_times(rows),
                columns=rr.TextLog.columns(text=[r[3] for r in rows], level=[r[2] for r in rows]),
            )

    def _write_statuses(
        self, rows: list[tuple[int, float, tuple[tuple[int, int], ...]]]
    ) -> Iterator[None]:
        # Each row holds the changes of one tick; the graph needs every node's colour per
        # row: the codes of all nodes are kept here and a row's colours read off them.
        # A step reads about STATUSES_PER_STEP node colours: a few rows of a big tree.
        nodes = len(self.index)
        per_step = max(1, STATUSES_PER_STEP // max(1, nodes))
        lanes: dict[int, list[tuple[int, float, str]]] = {}
        codes = self._codes
        colors = np.empty((len(rows), nodes), dtype=np.uint32)
        paths: list[tuple[int, float, tuple[int, ...] | None, np.ndarray]] = []
        for start in range(0, len(rows), per_step):
            for n, (tick, t, changes) in enumerate(rows[start : start + per_step], start):
                for i, code in changes:
                    codes[i] = code
                    lanes.setdefault(i, []).append((tick, t, STATES[code]))
                colors[n] = COLOR_TABLE[codes]
                shown = self._running_path(codes)
                if shown != self._path or any(
                    codes[i] != self._shown[k] for k, i in enumerate(shown)
                ):
                    self._path, self._shown = shown, codes[list(shown)].copy()
                    paths.append((tick, t, shown, colors[n][list(shown)]))
            yield
        if paths:
            self._write_paths(paths)
            yield
        self.rec.send_columns(
            f"{self.bt}/graph",
            indexes=_times(rows),
            columns=rr.GraphNodes.columns(colors=colors.reshape(-1)).partition([nodes] * len(rows)),
        )
        yield
        for n, (i, lane) in enumerate(lanes.items(), 1):
            self.rec.send_columns(
                status_path(self.index.nodes[i].key, self.bt),
                indexes=_times(lane),
                columns=rr.StateChange.columns(state=[r[2] for r in lane]),
            )
            if n % LANES_PER_STEP == 0:
                yield
        yield

    def _running_path(self, codes: np.ndarray) -> tuple[int, ...]:
        """The nodes of the running-path view: from the root down every running child (the
        first, for a parallel), with the children of each node on that path."""
        nodes, running = self.index.nodes, CODES[Status.RUNNING]
        shown, at = [0], 0
        while True:
            children = nodes[at].children
            shown.extend(children)
            at = next((c for c in children if codes[c] == running), -1)
            if at < 0:
                return tuple(shown)

    def _write_paths(
        self, rows: list[tuple[int, float, tuple[int, ...] | None, np.ndarray]]
    ) -> None:
        """The running path as its own small graph (``{bt}/path``), laid out level by level,
        each level centred: its nodes, labels, places and edges when they change (``shown``
        not None), its colours whenever they change (the viewer keeps the latest of each)."""
        ids: list[str] = []
        labels: list[str] = []
        positions: list[tuple[float, float]] = []
        edges: list[tuple[str, str]] = []
        lengths, edge_lengths = [], []
        for _, _, shown, _ in (r for r in rows if r[2] is not None):
            assert shown is not None
            layout = self._layouts.get(shown)
            if layout is None:
                layout = self._layouts[shown] = self._path_layout(shown)
            ids += layout.ids
            labels += layout.labels
            positions += layout.positions
            edges += layout.edges
            lengths.append(len(layout.ids))
            edge_lengths.append(len(layout.edges))
        path = f"{self.bt}/path"
        if lengths:
            times = _times([r for r in rows if r[2] is not None])
            self.rec.send_columns(
                path,
                indexes=times,
                columns=rr.GraphNodes.columns(
                    node_ids=ids, labels=labels, positions=np.array(positions, dtype=np.float32)
                ).partition(lengths),
            )
            self.rec.send_columns(
                path,
                indexes=times,
                # a (n, 2) array: rerun converts it column-wise, not pair by pair (5x less)
                columns=rr.GraphEdges.columns(
                    edges=np.array(edges, dtype=str).reshape(-1, 2)
                ).partition(edge_lengths),
            )
        self.rec.send_columns(
            path,
            indexes=_times(rows),
            columns=rr.GraphNodes.columns(colors=np.concatenate([r[3] for r in rows])).partition(
                [len(r[3]) for r in rows]
            ),
        )

    def _path_layout(self, shown: tuple[int, ...]) -> _PathLayout:
        """The running-path graph of ``shown``: each level centred under the one above."""
        nodes = self.index.nodes
        layout = _PathLayout([], [], [], [])
        by_depth: dict[int, list[int]] = {}
        for i in shown:
            by_depth.setdefault(nodes[i].depth, []).append(i)
        for level in by_depth.values():
            widths = [len(nodes[i].name) * PATH_CHAR + PATH_GAP for i in level]
            x = -sum(widths) / 2
            for i, w in zip(level, widths, strict=True):
                layout.ids.append(nodes[i].key)
                layout.labels.append(nodes[i].name)
                layout.positions.append((x + w / 2, nodes[i].depth * PATH_LEVEL))
                x += w
        for i in shown[1:]:
            parent = nodes[i].parent
            assert parent is not None
            layout.edges.append((nodes[parent].key, nodes[i].key))
        return layout

    def _write_stops(self, batch: Batch) -> None:
        """One lane per stop: reached (a drive to it succeeded), played (its content
        started), skipped; from the responses, ``start_poi`` and the blackboard."""
        moments: list[tuple[int, int, float, str, str]] = []  # tick, order, t, what, value
        for tick, t, role, value in batch.inputs:
            if role == "response" and value == 2:
                moments.append((tick, 0, t, "arrived", ""))
        for tick, t, side, channel, payload in batch.outputs:
            if side == "frontend" and channel == "start_poi":
                moments.append((tick, 1, t, "played", getattr(payload, "poi", "")))
        for tick, t, key, value in batch.blackboard:
            if key == "/target":
                moments.append((tick, 2, t, "target", value or ""))
            elif key == "/skipped" and value:
                moments.append((tick, 2, t, "skipped", value))
        lanes: dict[str, list[tuple[int, float, str]]] = {}
        for tick, _, t, what, value in sorted(moments, key=lambda m: m[:3]):
            if what == "target":
                self._target = value or None
                continue
            poi = self._target if what == "arrived" else value
            state = "reached" if what == "arrived" else what
            if poi in self.stops and self._stop_state.get(poi) != state:
                self._stop_state[poi] = state
                lanes.setdefault(poi, []).append((tick, t, state))
        for poi, rows in lanes.items():
            self.rec.send_columns(
                f"stops/{poi}",
                indexes=_times(rows),
                columns=rr.StateChange.columns(state=[r[2] for r in rows]),
            )

    def _write_poses(self, rows: list[tuple[int, float, float, float, float]]) -> Iterator[None]:
        xy = np.array([(r[2], r[3]) for r in rows], dtype=np.float64)
        yaw = np.array([r[4] for r in rows], dtype=np.float64)
        times = _times(rows)
        self.rec.send_columns("map/robot", indexes=times, columns=rr.Points2D.columns(positions=xy))
        yield
        self.rec.send_columns(
            "map/robot/heading",
            indexes=times,
            columns=rr.Arrows2D.columns(
                origins=xy, vectors=np.stack([6 * np.cos(yaw), 6 * np.sin(yaw)], axis=1)
            ),
        )
        trail_rows, strips = [], []
        for row in rows:
            point = (row[2], row[3])
            if not self._trail or math.dist(self._trail[-1], point) >= TRAIL_STEP:
                self._trail.append(point)
            self._poses_since_trail += 1
            if self._poses_since_trail >= TRAIL_EVERY:
                self._poses_since_trail = 0
                trail_rows.append(row)
                strips.append(np.array(self._trail, dtype=np.float32))
        yield
        if trail_rows:
            self.rec.send_columns(
                "map/robot/trail",
                indexes=_times(trail_rows),
                columns=rr.LineStrips2D.columns(strips=strips),
            )
            yield

    def _read_inputs(
        self, batch: Batch, logs: dict[str, list[tuple[int, float, str, str]]], goals: list[GoalRow]
    ) -> Iterator[None]:
        scalars: dict[str, list[tuple[int, float, float]]] = {}
        visitors: list[tuple[int, float, Any]] = []
        people: list[tuple[int, float, Any]] = []
        faces: dict[int, list[tuple[int, float, float]]] = {}
        ros_log: list[tuple[int, float, str, str]] = []
        for tick, t, role, value in batch.inputs:
            if role == "persons":
                visitors.append((tick, t, value.persons))
                scalars.setdefault("plots/people/persons", []).append((tick, t, len(value.persons)))
            elif role == "people":
                people.append((tick, t, value.people))
                scalars.setdefault("plots/people/people", []).append((tick, t, len(value.people)))
            elif role == "faces":
                for face in value.faces:
                    faces.setdefault(face.id, []).append((tick, t, face.engagement))
            elif role == "diagnostic":
                if value.battery is not None:
                    scalars.setdefault("plots/battery", []).append((tick, t, value.battery))
                if value.faults != self._faults:
                    self._faults = value.faults
                    ros_log.append(
                        (
                            tick,
                            t,
                            "WARN" if value.faults else "INFO",
                            "faults: " + ("; ".join(value.faults) or "none"),
                        )
                    )
            elif role == "response":
                code = Response.of(value)
                name = code.word if code is not None else "unknown"
                level = "WARN" if code in (FAILED, ABORTED) else "INFO"
                ros_log.append((tick, t, level, f"/FROG_response {value} ({name})"))
                if code is not None and code.terminal:
                    goals.append((tick, 0, t, None))
            elif role == "docking_state" and value != self._docking:
                self._docking = value
                level = "WARN" if value == DockingState.FAILED else "INFO"
                ros_log.append((tick, t, level, f"docking state: {value}"))
        logs["log/ros/in"] = [
            (tick, t, level, "← robot " + text) for tick, t, level, text in ros_log
        ]
        for path, rows in scalars.items():
            self.rec.send_columns(
                path, indexes=_times(rows), columns=rr.Scalars.columns(scalars=[r[2] for r in rows])
            )
            yield
        for face_id, rows in faces.items():
            path = f"plots/engagement/faces/{face_id}"
            if face_id not in self._faces:
                self._faces.add(face_id)
                self.rec.log(
                    path,
                    rr.SeriesLines(names=f"face {face_id}", colors=FACE, widths=1.0),
                    static=True,
                )
            self.rec.send_columns(
                path, indexes=_times(rows), columns=rr.Scalars.columns(scalars=[r[2] for r in rows])
            )
            yield
        if visitors:
            self._write_people("map/visitors", visitors, labelled=True)
            yield
        if people:
            self._write_people("map/people", people, labelled=False)
            yield

    def _write_people(
        self, path: str, rows: list[tuple[int, float, Any]], *, labelled: bool
    ) -> None:
        positions = [(p.position.x, p.position.y) for _, _, ps in rows for p in ps]
        lengths = [len(ps) for _, _, ps in rows]
        xy = np.array(positions, dtype=np.float64).reshape(-1, 2)
        if not labelled:
            columns = rr.Points2D.columns(positions=xy)
        else:
            lo, hi = self.facing
            persons = [p for _, _, ps in rows for p in ps]
            facing = [lo < p.orientation < hi for p in persons]
            columns = rr.Points2D.columns(
                positions=xy,
                colors=np.array([FACING if f else NOT_FACING for f in facing], dtype=np.uint32),
                labels=[str(p.id) for p in persons],
            )
        self.rec.send_columns(path, indexes=_times(rows), columns=columns.partition(lengths))

    def _read_outputs(
        self, batch: Batch, logs: dict[str, list[tuple[int, float, str, str]]], goals: list[GoalRow]
    ) -> None:
        for tick, t, side, channel, payload in batch.outputs:
            if side == "frontend":
                level = (
                    "WARN"
                    if getattr(payload, "state", "") == "aborted"
                    else "DEBUG"
                    if channel in PERIODIC
                    else "INFO"
                )
                logs.setdefault("log/frontend/out", []).append(
                    (tick, t, level, "→ front end " + _describe(payload))
                )
                continue
            out: RobotCommand = payload
            role = out.role
            text = f"{channel} {out.msg.get('data', '')}".rstrip()
            if role == "icl":  # stray samples after a stop must not bridge two sessions
                self._end_face_session(tick, t)
            if role == "goto" and isinstance(out.value, Pose) and out.goal is not None:
                pose, name = out.value, out.goal.target
                text = f"{channel} {name} ({pose.x:.1f}, {pose.y:.1f})"
                goals.append((tick, 1, t, (name, pose.x, pose.y, pose.yaw)))
            elif role == "approach":
                goals.append((tick, 1, t, None))
            logs.setdefault("log/ros/out", []).append((tick, t, "INFO", "→ robot " + text))

    def _read_blackboard(self, batch: Batch) -> None:
        meter, decision = [], []
        for tick, t, key, value in batch.blackboard:
            if key == "/engagement_meter" and isinstance(value, int | float):
                meter.append((tick, t, float(value)))
            elif key == "/engagement_decision" and value is not None:
                engaged = getattr(value[-1] if isinstance(value, tuple) else value, "engaged", None)
                if engaged is not None:
                    decision.append((tick, t, 1.0 if engaged else -1.0))
        for path, rows in (
            ("plots/engagement/meter", meter),
            ("plots/engagement/decision", decision),
        ):
            if rows:
                self.rec.send_columns(
                    path,
                    indexes=_times(rows),
                    columns=rr.Scalars.columns(scalars=[r[2] for r in rows]),
                )

    def _end_face_session(self, tick: int, t: float) -> None:
        """Break the engagement lines between face-stream sessions (a clear is a gap in a
        time series), at the stop and again at the next start."""
        self._set_time(tick, t)
        for path in (
            "plots/engagement/meter",
            *(f"plots/engagement/faces/{face_id}" for face_id in self._faces),
        ):
            self.rec.log(path, rr.Clear(recursive=False))

    def _set_time(self, tick: int, t: float) -> None:
        self.rec.set_time(TICK, sequence=tick)
        self.rec.set_time(TIME, timestamp=np.datetime64(site_ns(t), "ns"))

    def _log_goal(self, tick: int, t: float, goal: Goal | None) -> None:
        rec = self.rec
        self._set_time(tick, t)
        if goal is None:
            rec.log("map/goal", rr.Clear(recursive=True))
            self._goal = None
            return
        name, x, y, yaw = goal
        rec.log(
            "map/goal",
            rr.Points2D(
                [(x, y)],
                radii=R_GOAL,
                colors=GOAL,
                labels=f"goal {name}",
                show_labels=False,
                draw_order=45,
            ),
        )
        rec.log(
            "map/goal/heading",
            rr.Arrows2D(
                origins=[(x, y)],
                vectors=[(4 * math.cos(yaw), 4 * math.sin(yaw))],
                radii=R_ARROW * 1.5,
                colors=GOAL,
                draw_order=46,
            ),
        )
        self._goal = goal


def _describe(message: Any) -> str:
    """``start_poi poi=POI1 waypoint=POI1a part=a`` (empty fields left out)."""
    fields = " ".join(
        f"{k}={v:.2f}" if isinstance(v, float) else f"{k}={v}"
        for k, v in message_fields(message).items()
        if v != ""
    )
    return f"{message.type} {fields}".rstrip()
