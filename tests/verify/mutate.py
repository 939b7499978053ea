"""Copies of the shipped trees with one edit, for verify's tests."""

from __future__ import annotations

import shutil
from pathlib import Path

from frog_bt import resources
from frog_bt.behaviours import FACTORY
from frog_bt.config import Site, load_site
from frog_bt.tree.factory import NodeFactory
from frog_bt.verify.graph import Run
from frog_bt.verify.prove import Verdict, prove
from frog_bt.verify.report import tick_line


def copy(tmp_path: Path, edits: dict[str, list[tuple[str, str]]]) -> Path:
    """The shipped trees in ``tmp_path/trees`` with ``edits`` (file -> [(old, new)]) made;
    the path of the copied tour.yaml. Each ``old`` must be there once."""
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    for name, changes in edits.items():
        text = (trees / name).read_text()
        for old, new in changes:
            assert text.count(old) == 1, f"{name}: {old!r} is not there once"
            text = text.replace(old, new)
        (trees / name).write_text(text)
    return trees / "tour.yaml"


def site() -> Site:
    return load_site(None)


def verdict(tour: Path | None, factory: NodeFactory = FACTORY) -> Verdict:
    s = site()
    return prove(factory.load(tour, s), s)


def run_of(v: Verdict, name: str) -> Run:
    """The run that breaks property ``name`` (it must be broken)."""
    found = [b for b in v.broken if b.name == name]
    assert found, f"{name} holds; broken: {[b.name for b in v.broken]}"
    return found[0].run


def lines(v: Verdict, run: Run) -> list[str]:
    return [tick_line(v.model, step) for _, step, _ in run.ticks]
