"""Our nodes run py_trees' ``stop`` without formatting its debug message (py_trees builds
it eagerly, debug logging on or not: half the time verify spent stopping nodes). The
quiet stops must do exactly what py_trees' do: every run of a tour, explored with
py_trees' own stops (its debug logging on, its output dropped) and with the quiet ones,
is the same graph, state for state and tick for tick."""

from __future__ import annotations

from importlib.metadata import version
from pathlib import Path

import py_trees
import pytest

from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.config import load_site
from frog_bt.engine import observed
from frog_bt.tree.composites import COMPOSITES
from frog_bt.verify.explore import Graph
from frog_bt.verify.prove import prove
from tests.verify.test_real import FACTORY_, tour


def test_every_node_type_stops_quietly() -> None:
    """Each node type a tree file can name reaches one of py_trees' own stops, which the
    quiet ones copy (py_trees 2.6: a new py_trees is checked again before it is trusted)."""
    assert version("py_trees").startswith("2.6."), version("py_trees")
    types = [*LEAF_TYPES, *DECORATOR_TYPES, *COMPOSITES.values()]
    loud = [t.__name__ for t in types if observed._quiet_stop(t) is observed._loud]
    assert loud == []


def _explored(path: Path) -> Graph:
    site = load_site(None)
    return prove(FACTORY_.load(path, site), site, properties=[], restarts=False).graph


def test_quiet_stops_explore_the_same_graph_as_py_trees_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tour(tmp_path)  # a small tour: its stops cascade through every kind of node
    quiet = _explored(path)
    calls: list[str] = []
    monkeypatch.setattr(py_trees.logging, "level", py_trees.logging.Level.DEBUG)
    monkeypatch.setattr(py_trees.console, "logdebug", calls.append)
    loud = _explored(path)
    assert any(".stop(" in c for c in calls)  # py_trees' own stops ran, and logged
    assert len(quiet.states) > 40 and quiet.states == loud.states
    assert quiet.starts == loud.starts
    assert [[(d, s.ticked, s.choices) for d, s in e] for e in quiet.edges] == [
        [(d, s.ticked, s.choices) for d, s in e] for e in loud.edges
    ]
