"""``frog-bt leaves`` lists what ``frog-bt verify`` proves and the templates a tree file
may add."""

from __future__ import annotations

import pytest

from frog_bt.cli import main
from frog_bt.verify.properties import BUILT_IN


def test_leaves_lists_the_properties_and_the_templates(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["leaves"]) == 0
    out = capsys.readouterr().out
    assert "### Properties (`frog-bt verify`)" in out
    assert all(f"| `{name}` |" in out for name in BUILT_IN)
    for template, fields in (
        ("Together", "`never`, `together`"),
        ("Reaches", "`after`, `within`, `reaches`"),
        ("Between", "`between`, `never`"),
    ):
        assert f"| `{template}` | {fields} |" in out
