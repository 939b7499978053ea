"""The tree numbering and the graph's tidy layout: parents above children, no overlaps."""

from __future__ import annotations

import itertools

import py_trees
from hypothesis import given, settings
from hypothesis import strategies as st

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.live.telemetry.layout import GAP, TreeIndex, label_width, node_key, tidy_layout

Behaviour = py_trees.behaviour.Behaviour


def tour_index() -> TreeIndex:
    site = load_site()
    return TreeIndex.of(load_tree(site=site).root)


def check_layout(index: TreeIndex, positions: list[tuple[float, float]]) -> None:
    widths = [label_width(n.name) for n in index.nodes]
    for node in index.nodes:
        x, y = positions[node.index]
        if node.parent is not None:
            assert y > positions[node.parent][1], f"{node.key} is not below its parent"
        if node.children:
            first, last = positions[node.children[0]][0], positions[node.children[-1]][0]
            assert abs(x - (first + last) / 2) < 1e-6, f"{node.key} is not centred"
            xs = [positions[c][0] for c in node.children]
            assert xs == sorted(xs), f"children of {node.key} are out of order"
    by_depth: dict[float, list[int]] = {}
    for node in index.nodes:
        by_depth.setdefault(positions[node.index][1], []).append(node.index)
    for row in by_depth.values():
        row.sort(key=lambda i: positions[i][0])
        for a, b in itertools.pairwise(row):
            right_of_a = positions[a][0] + widths[a] / 2
            left_of_b = positions[b][0] - widths[b] / 2
            assert left_of_b - right_of_a >= GAP - 1e-6, (
                f"{index.nodes[a].key} and {index.nodes[b].key} overlap"
            )


def test_tour_tree_layout_is_tidy():
    index = tour_index()
    positions = tidy_layout(index)
    assert len(positions) == len(index) > 50
    assert positions[0] == (0.0, 0.0)
    check_layout(index, positions)


def test_nodes_are_numbered_in_pre_order_with_unique_sortable_keys():
    index = tour_index()
    keys = [n.key for n in index.nodes]
    assert len(set(keys)) == len(keys)
    assert keys == sorted(keys)  # lanes sort like the tree
    assert index.nodes[0].parent is None and index.nodes[0].depth == 0
    assert [b.name for b in index.behaviours] == [n.name for n in index.nodes]
    for node in index.nodes[1:]:
        parent = index.nodes[node.parent]
        assert node.index in parent.children and node.depth == parent.depth + 1
    assert len(index.edges()) == len(index) - 1
    assert index.sizes()[0] == len(index)


def test_node_keys_need_no_escaping():
    assert node_key(7, "Navigate POI0", 3) == "007_Navigate_POI0"
    assert node_key(12, "Face stream (introduction)") == "12_Face_stream_introduction"
    assert node_key(3, "Tell more?") == "03_Tell_more"
    assert node_key(4, "Lion's Courtyard") == "04_Lion_s_Courtyard"


def test_phases_are_the_steps_of_the_big_branches():
    index = tour_index()
    phases = index.phases()
    assert phases == sorted(phases)
    assert len(phases) < len(index) // 4
    stops = next(n for n in index.nodes if n.name == "Stops")
    assert stops.index in phases
    assert set(stops.children) <= set(phases)  # one lane per stop of the tour
    assert len(stops.children) == len(load_site().tour.stops)
    sizes = index.sizes()
    for i in phases:  # a phase is a step of a big branch
        parent = index.nodes[i].parent
        assert parent is not None and len(index.nodes[parent].children) > 1
        assert sizes[parent] >= 0.2 * len(index)


def _tree(shape: list, counter: list[int]) -> Behaviour:
    counter[0] += 1
    name = f"node {counter[0]}" + "x" * (counter[0] * 7 % 13)
    if not shape:
        return py_trees.behaviours.Success(name=name)
    return py_trees.composites.Sequence(
        name=name, memory=True, children=[_tree(s, counter) for s in shape]
    )


shapes = st.recursive(
    st.just([]), lambda inner: st.lists(inner, min_size=1, max_size=5), max_leaves=40
)


@settings(max_examples=60, deadline=None)
@given(shapes)
def test_any_tree_layout_is_tidy(shape: list):
    index = TreeIndex.of(_tree(shape, [0]))
    check_layout(index, tidy_layout(index))


def test_site_time_reads_as_the_sites_clocks_also_across_summer_time():
    from datetime import UTC, datetime

    from frog_bt.live.telemetry.layout import site_ns

    def local(*utc: int) -> datetime:
        t = datetime(*utc, tzinfo=UTC).timestamp()
        return datetime.fromtimestamp(site_ns(t) / 1e9, UTC).replace(tzinfo=None)

    assert local(2026, 1, 15, 12, 0) == datetime(2026, 1, 15, 13, 0)  # CET, +1
    assert local(2026, 7, 1, 8, 30) == datetime(2026, 7, 1, 10, 30)  # CEST, +2
    # summer time begins at 01:00 UTC on 29 March 2026: 01:59:59 is followed by 03:00
    assert local(2026, 3, 29, 0, 59, 59) == datetime(2026, 3, 29, 1, 59, 59)
    assert local(2026, 3, 29, 1, 0, 0) == datetime(2026, 3, 29, 3, 0, 0)
