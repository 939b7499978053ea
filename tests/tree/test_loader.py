"""Tree files are checked whole before anything connects; errors name file, path and expectation."""

from __future__ import annotations

import re

import pytest
from bench import write_tree

from frog_bt.behaviours import load_tree
from frog_bt.config import load_site
from frog_bt.errors import TreeError


@pytest.fixture(scope="module")
def site():
    return load_site()


def error_of(tmp_path, text, site, name="t.yaml"):
    path = write_tree(tmp_path, text, name)
    with pytest.raises(TreeError) as info:
        load_tree(path, site)
    return without_lines(str(info.value).replace(str(tmp_path) + "/", ""))


def without_lines(message: str) -> str:
    """``t.yaml:3:7: root...`` as ``t.yaml: root...`` (the line is checked on its own)."""
    return re.sub(r"\.yaml:\d+:\d+:", ".yaml:", message)


def test_an_error_names_the_line_and_column_of_its_node(tmp_path, site):
    path = write_tree(
        tmp_path,
        "root:\n  type: Sequence\n  memory: true\n  children:\n"
        "    - {type: Navigate, poi: POI1, speed: 3}\n",
    )
    with pytest.raises(TreeError) as info:
        load_tree(path, site)
    assert str(info.value) == f"{path}:5:42: root.children[0].speed: unknown key"
    assert info.value.line == (5, 42)  # the value of the key


def test_the_shipped_tour_loads_and_has_every_stop(site):
    tree = load_tree(site=site)
    names = [n.name for n in tree.nodes()]
    for stop in site.tour.stops:
        assert f"Visit {stop.poi}" in names
    assert tree.root.name == "Location awareness"
    assert [n.name for n in tree.root.decorated.children] == ["Abort politely", "Tour, or give up"]
    # TEMP has no content and no follower check
    present_temp = next(n for n in tree.nodes() if n.name == "Present TEMP")
    assert present_temp.children == []


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            "root: {type: Navigat, poi: POI1}",
            "t.yaml: root.type: unknown type 'Navigat'; did you mean 'Navigate'?",
        ),
        (
            "root: {type: Sequence, children: [{type: FinishPoi, poi: POI1}]}",
            "t.yaml: root.memory: missing required key: a Sequence must say memory: true or false",
        ),
        (
            "root: {type: Sequence, memory: yes please, children: [{type: FinishPoi, poi: POI1}]}",
            "t.yaml: root.memory: expected true or false, got 'yes please'",
        ),
        ("root: {type: Navigate, poi: POI1, speed: 3}", "t.yaml: root.speed: unknown key"),
        ("root: {type: Navigate}", "t.yaml: root.poi: missing required key"),
        (
            "root: {type: Navigate, poi: POI1, timeout: soon}",
            "t.yaml: root.timeout: Input should be a valid number",
        ),
        ("root: {type: Navigate, poi: POI9}", "t.yaml: root.poi: unknown POI 'POI9' (known: END,"),
        ("root: {type: Docking, action: park}", "t.yaml: root.action: Input should be 'dock' or"),
        (
            "root: {type: Selector, memory: false, children: []}",
            "t.yaml: root.children: expected a non-empty list of nodes",
        ),
        (
            "root: {type: Retry, attempts: 0, child: {type: FinishPoi, poi: POI1}}",
            "t.yaml: root.attempts: Input should be greater than or equal to 1",
        ),
        (
            "root: {type: Sequence, memory: true, children: [{type: WaitAnswer}]}",
            "t.yaml: root.children[0]: WaitAnswer 'WaitAnswer' reads /visitor: nothing writes it",
        ),
        (
            "root: {type: Sequence, memory: true, children: [{include: missing.yaml}]}",
            "t.yaml: root.children[0].include: no such file: missing.yaml",
        ),
        ("root: {type: FinishPoi, poi: '{place}'}", "t.yaml: root.poi: unknown variable 'place'"),
        ("root: {type: FinishPoi, poi: POI1, when: sunny}", "t.yaml: root.when: unknown variable"),
        ("rot: {type: FinishPoi, poi: POI1}", "t.yaml: rot: unknown key"),
        ("root: [1, 2]", "t.yaml: root: expected a node (a mapping), got [1, 2]"),
        (
            "root: {type: Sequence, memory: true\n",
            "t.yaml: not valid YAML: expected ',' or '}', but got '<stream end>'",
        ),
    ],
)
def test_errors_name_file_path_and_expectation(tmp_path, site, text, expected):
    assert expected in error_of(tmp_path, text, site)


def test_a_yaml_syntax_error_is_file_line_col_as_every_other_error(tmp_path, site):
    path = write_tree(tmp_path, "root:\n  type: Sequence\n   memory: true\n", "t.yaml")
    with pytest.raises(TreeError) as info:
        load_tree(path, site)
    assert str(info.value).startswith(f"{path}:3:10: not valid YAML: ")


def test_error_inside_an_included_file_names_that_file(tmp_path, site):
    write_tree(tmp_path, "root: {type: Navigate, poi: POI1, colour: red}", "inner.yaml")
    message = error_of(
        tmp_path, "root: {type: Sequence, memory: true, children: [{include: inner.yaml}]}", site
    )
    assert message.startswith("inner.yaml: root.colour: unknown key")


def test_a_missing_include_is_named_at_the_line_that_includes_it(tmp_path, site):
    path = write_tree(
        tmp_path,
        "root:\n  type: Sequence\n  memory: true\n  children:\n    - {include: gone.yaml}\n",
    )
    with pytest.raises(TreeError) as info:
        load_tree(path, site)
    message = str(info.value).replace(str(tmp_path) + "/", "")
    assert message == "t.yaml:5:17: root.children[0].include: no such file: gone.yaml"


def test_self_inclusion_is_refused(tmp_path, site):
    message = error_of(
        tmp_path, "root: {type: Sequence, memory: true, children: [{include: t.yaml}]}", site
    )
    assert "includes itself" in message


def test_foreach_expands_one_subtree_per_stop_with_its_variables(tmp_path, site):
    write_tree(
        tmp_path,
        """
        root:
          type: Sequence
          name: "stop {poi}"
          memory: true
          children:
            - {type: FinishPoi, poi: "{poi}", when: content}
            - {type: FinishPoi, name: "faces at {poi}", poi: "{poi}", when: face_stream}
        """,
        "stop.yaml",
    )
    path = write_tree(
        tmp_path,
        "root: {type: Sequence, memory: true, children: [{foreach: stops, include: stop.yaml}]}",
    )
    tree = load_tree(path, site)
    tops = [c.name for c in tree.root.children]
    assert tops == [f"stop {s.poi}" for s in site.tour.stops]
    faces = [n.name for n in tree.nodes() if n.name.startswith("faces at")]
    assert faces == ["faces at POI1", "faces at POI2"]


def test_whole_string_variable_keeps_its_type(tmp_path, site):
    path = write_tree(
        tmp_path,
        "root: {type: Retry, attempts: '{nav_attempts}', child: {type: FinishPoi, poi: POI1}}",
    )
    tree = load_tree(path, site)
    assert tree.root.params.attempts == site.navigation.attempts


def test_when_on_a_decorator_leaves_out_that_decorator_only(tmp_path, site):
    """One switch, `when`: a decorator left out leaves its child in place; a composite or
    a leaf left out goes with all it holds."""
    path = write_tree(
        tmp_path,
        """
        root:
          type: Sequence
          memory: true
          children:
            - type: FaceStream
              when: not dock_attempts
              child: {type: FinishPoi, poi: POI1}
            - type: Retry
              attempts: 2
              child: {type: FinishPoi, poi: POI2, when: not dock_attempts}
    """,
    )
    tree = load_tree(path, site)
    assert [type(n).__name__ for n in tree.root.iterate()] == ["FinishPoi", "Sequence"]
    assert [n.name for n in tree.root.children] == ["FinishPoi POI1"]
