"""JSON Schemas for tree files and the site config: generated from the models, shipped
beside the files (which point at them), and every shipped file validates."""

from __future__ import annotations

from pathlib import Path

import jsonschema
import pytest
import yaml

from frog_bt import resources
from frog_bt.behaviours import FACTORY
from frog_bt.cli import main
from frog_bt.tree.schema import (
    SITE_SCHEMA_FILE,
    TREE_SCHEMA_FILE,
    dumps,
    site_schema,
    tree_schema,
)

TREES = sorted(resources.tree_dir().glob("*.yaml"))
SITE = resources.site_dir() / resources.SITE_FILE


def validator(schema: dict) -> jsonschema.Draft202012Validator:
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_the_shipped_schemas_are_the_generated_ones() -> None:
    assert (resources.tree_dir() / TREE_SCHEMA_FILE).read_text() == dumps(tree_schema(FACTORY)), (
        "run: frog-bt schema tree > trees/tree.schema.json"
    )
    assert (resources.site_dir() / SITE_SCHEMA_FILE).read_text() == dumps(site_schema()), (
        "run: frog-bt schema site > config/site.schema.json"
    )


@pytest.mark.parametrize("path", TREES, ids=lambda p: p.name)
def test_every_shipped_tree_validates_and_points_at_the_schema(path: Path) -> None:
    text = path.read_text()
    assert text.startswith(f"# yaml-language-server: $schema={TREE_SCHEMA_FILE}\n")
    assert list(validator(tree_schema(FACTORY)).iter_errors(yaml.safe_load(text))) == []


def test_the_shipped_site_validates_and_points_at_the_schema() -> None:
    text = SITE.read_text()
    assert text.startswith(f"# yaml-language-server: $schema={SITE_SCHEMA_FILE}\n")
    assert list(validator(site_schema()).iter_errors(yaml.safe_load(text))) == []


@pytest.mark.parametrize(
    "root",
    [
        {"type": "Navigat", "poi": "POI1"},  # unknown type
        {"type": "Navigate", "poi": "POI1", "speed": 3},  # unknown parameter
        {"type": "Navigate"},  # missing parameter
        {"type": "Sequence", "children": [{"type": "FinishPoi", "poi": "POI1"}]},  # no memory
        {"type": "Retry", "attempts": 0, "child": {"type": "GiveUp"}},  # out of range
        {"type": "PlayContent", "poi": "POI1", "part": "c"},
    ],
)
def test_mistakes_are_flagged(root: dict) -> None:
    assert list(validator(tree_schema(FACTORY)).iter_errors({"root": root}))


def test_variables_are_accepted_for_any_parameter() -> None:
    tree = {
        "root": {
            "type": "Retry",
            "attempts": "{nav_attempts}",
            "child": {"type": "Navigate", "poi": "{poi}"},
        }
    }
    assert list(validator(tree_schema(FACTORY)).iter_errors(tree)) == []


def test_schema_command(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schema", "site"]) == 0
    assert capsys.readouterr().out == dumps(site_schema())
