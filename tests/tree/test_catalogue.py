"""``frog-bt leaves``: every registered node type, and docs/TREES.md's node reference
is exactly its Markdown."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from frog_bt.behaviours import FACTORY
from frog_bt.cli import main
from frog_bt.tree.catalogue import as_markdown, catalogue

TREES_MD = Path(__file__).resolve().parents[2] / "docs" / "TREES.md"


def test_every_registered_type_is_listed_with_its_keys() -> None:
    nodes = {n.name: n for n in catalogue(FACTORY)}
    assert set(nodes) == {"Sequence", "Selector", "Parallel", *FACTORY.leaves, *FACTORY.decorators}
    for name in ("MustAbort", "ClearAbort", "GiveUp", "ConfirmResume", "Checkpointed"):
        assert name in nodes
    seek = nodes["SeekVisitor"]
    assert seek.kind == "leaf" and seek.writes == ("/visitor",) and "/persons" in seek.reads
    retry = {p.name: p for p in nodes["Retry"].params}
    assert retry["attempts"].default is None and "until it succeeds" in retry["attempts"].meaning


def test_the_docs_node_reference_is_the_catalogue() -> None:
    text = TREES_MD.read_text()
    start = text.index("<!-- leaves:begin -->\n") + len("<!-- leaves:begin -->\n")
    end = text.index("<!-- leaves:end -->")
    assert text[start:end] == as_markdown(catalogue(FACTORY)), (
        "docs/TREES.md is out of date: paste `frog-bt leaves` between the leaves markers"
    )


def test_json_format(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["leaves", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    navigate = next(n for n in data if n["name"] == "Navigate")
    assert [p["name"] for p in navigate["params"]] == ["poi", "timeout"]
    assert navigate["params"][0]["default"] == "required"
