"""The behaviour tree as numbered nodes with a tidy top-down layout (no rerun here).

:class:`TreeIndex` numbers the nodes of a tree in depth-first pre-order (the
order a reader scans a tree file in), so status lanes sort like the tree and
every node has a unique, stable id even when two nodes share a name.

:func:`tidy_layout` places the nodes for the graph view: depth gives ``y``
(root at the top), and each subtree is packed against its left neighbours as
closely as its widest level allows (Reingold-Tilford style contours), with a
parent centred over its children. Node widths follow label lengths, so long
names never overlap at any depth.
"""

from __future__ import annotations

import dataclasses
import functools
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime

import py_trees

from frog_bt.clock import SITE_TZ

Behaviour = py_trees.behaviour.Behaviour

CHAR_WIDTH = 6.8  # graph-view units per label character (rerun 0.41's UI font, measured)
NODE_PADDING = 12.0  # around each label's box
GAP = 10.0  # between neighbouring boxes on one level
LEVEL_HEIGHT = 56.0  # between depths
PHASE_SHARE = 0.2  # a branch with this share of the nodes is itself split into phases
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


@dataclass(frozen=True, slots=True)
class TreeNode:
    """One behaviour of the tree: its pre-order number, depth and parent number."""

    index: int
    name: str
    kind: str  # class name: Sequence, Retry, Navigate, ...
    depth: int
    parent: int | None
    children: tuple[int, ...]
    key: str = ""  # unique, sorts in tree order, needs no escaping: "007_Navigate_POI0"


@dataclass
class TreeIndex:
    """The nodes of a tree in pre-order, with the behaviours they stand for."""

    nodes: list[TreeNode] = field(default_factory=list)
    behaviours: list[Behaviour] = field(default_factory=list)

    @classmethod
    def of(cls, root: Behaviour) -> TreeIndex:
        index = cls()
        index._add(root, 0, None)
        digits = len(str(len(index.nodes) - 1))
        index.nodes = [
            dataclasses.replace(n, key=node_key(n.index, n.name, digits)) for n in index.nodes
        ]
        return index

    def _add(self, behaviour: Behaviour, depth: int, parent: int | None) -> int:
        number = len(self.nodes)
        self.nodes.append(
            TreeNode(number, behaviour.name, type(behaviour).__name__, depth, parent, ())
        )
        self.behaviours.append(behaviour)
        children = tuple(self._add(child, depth + 1, number) for child in behaviour.children)
        node = self.nodes[number]
        self.nodes[number] = TreeNode(node.index, node.name, node.kind, depth, parent, children)
        return number

    def __len__(self) -> int:
        return len(self.nodes)

    def edges(self) -> list[tuple[int, int]]:
        """(parent, child) pairs, in pre-order."""
        return [(n.parent, n.index) for n in self.nodes if n.parent is not None]

    def sizes(self) -> list[int]:
        """Number of nodes in each node's subtree (itself included)."""
        sizes = [1] * len(self.nodes)
        for node in reversed(self.nodes):
            if node.parent is not None:
                sizes[node.parent] += sizes[node.index]
        return sizes

    def phases(self, share: float = PHASE_SHARE) -> list[int]:
        """The nodes that tell where a run is, in tree order: the steps of the top
        composite, and again the steps of any step holding ``share`` of all nodes
        (for the tour: undock, guide a visitor, dock, ...; then go to POI0, recruit,
        stops; then each stop). Single-child chains (decorators) are walked through.
        """
        if not self.nodes:
            return []
        sizes, big = self.sizes(), share * len(self.nodes)
        out: list[int] = []

        def split(i: int) -> None:
            while len(self.nodes[i].children) == 1:
                i = self.nodes[i].children[0]
            for child in self.nodes[i].children:
                out.append(child)
                if sizes[child] >= big:
                    split(child)

        split(0)
        return out or [0]


def node_key(index: int, name: str, digits: int = 2) -> str:
    """``node_key(7, "Navigate POI0", 3) == "007_Navigate_POI0"`` (status lanes, graph ids)."""
    return f"{index:0{digits}d}_{_UNSAFE.sub('_', name)}".rstrip("_")


def label_width(label: str) -> float:
    """Estimated width of a node's box in graph-view units."""
    return len(label) * CHAR_WIDTH + NODE_PADDING


@dataclass(slots=True)
class _Shape:
    """A laid-out subtree: x offsets relative to its root, and per-depth extents."""

    offsets: dict[int, float]  # node index -> x relative to the subtree root
    left: list[float]  # per level below (and including) the root: leftmost edge
    right: list[float]  # ... rightmost edge


def tidy_layout(
    index: TreeIndex,
    widths: Sequence[float] | None = None,
    gap: float = GAP,
    level_height: float = LEVEL_HEIGHT,
) -> list[tuple[float, float]]:
    """(x, y) centre of every node, in index order; the root is at (0, 0), children below."""
    if not index.nodes:
        return []
    widths = list(widths) if widths is not None else [label_width(n.name) for n in index.nodes]
    shapes: dict[int, _Shape] = {}
    for node in reversed(index.nodes):  # children before parents
        shapes[node.index] = _shape(node, shapes, widths, gap)
    root = shapes[0]
    return [(root.offsets[n.index], n.depth * level_height) for n in index.nodes]


def _shape(
    node: TreeNode, shapes: dict[int, _Shape], widths: Sequence[float], gap: float
) -> _Shape:
    half = widths[node.index] / 2
    if not node.children:
        return _Shape({node.index: 0.0}, [-half], [half])
    # Place each child subtree just right of the ones before it, level by level.
    placed: list[tuple[float, _Shape]] = []
    right: list[float] = []  # running right contour of the children placed so far
    for child in node.children:
        shape = shapes.pop(child)
        shift = 0.0
        if placed:
            shift = max(r - left + gap for r, left in zip(right, shape.left, strict=False))
        placed.append((shift, shape))
        for level, edge in enumerate(shape.right):
            if level < len(right):
                right[level] = max(right[level], shift + edge)
            else:
                right.append(shift + edge)
    centre = (placed[0][0] + placed[-1][0]) / 2
    offsets = {node.index: 0.0}
    levels = max(len(s.left) for _, s in placed)
    left_edges = [float("inf")] * levels
    right_edges = [float("-inf")] * levels
    for shift, shape in placed:
        for i, x in shape.offsets.items():
            offsets[i] = x + shift - centre
        for level in range(len(shape.left)):
            left_edges[level] = min(left_edges[level], shape.left[level] + shift - centre)
            right_edges[level] = max(right_edges[level], shape.right[level] + shift - centre)
    return _Shape(offsets, [-half, *left_edges], [half, *right_edges])


TICK, TIME = "tick", "site time"  # the timelines: tick number, project clock at the site


def site_offset(t: float) -> float:
    """Seconds the site's clocks are ahead of UTC at ``t`` (Europe/Madrid: 3600 or 7200).

    The ``site time`` timeline is the project clock as the site's wall clocks read it,
    stored as if it were UTC: rerun 0.41 shows timestamps in UTC (its *Local* setting
    fails on Linux, rerun-io/rerun#6277), and the report and the console show site
    time, so 10:32 in either finds 10:32 in the viewer (whose trailing ``Z`` is not UTC
    here). Also right after a change of summer time: each row is shifted by its own
    instant's offset."""
    return _offset(int(t // 900))


@functools.lru_cache(maxsize=64)
def _offset(quarter: int) -> float:
    # zones change their offset on a quarter of an hour: one lookup per quarter
    offset = datetime.fromtimestamp(quarter * 900, UTC).astimezone(SITE_TZ).utcoffset()
    return offset.total_seconds() if offset is not None else 0.0


def site_ns(t: float) -> int:
    """``t`` (seconds since the epoch) on the ``site time`` timeline, in nanoseconds."""
    return round((t + site_offset(t)) * 1e9)


def status_path(key: str, bt: str = "bt") -> str:
    """The status lane of a node (keys need no escaping, see TreeNode.key); ``bt`` is the
    tree's root entity (``bt``, ``bt/tree2`` for the first reloaded tree, ...)."""
    return f"{bt}/status/{key}"
