"""docs/RELIABILITY.md names real tests: every ``path::name`` in it is defined."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
REF = re.compile(r"`(tests/[\w/]+\.py)::(\w+)`")


def test_every_test_named_in_reliability_md_exists() -> None:
    refs = REF.findall((ROOT / "docs" / "RELIABILITY.md").read_text(encoding="utf-8"))
    assert len(refs) > 20
    missing = []
    for path, name in refs:
        tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
        defined = {n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)}
        if name not in defined:
            missing.append(f"{path}::{name}")
    assert missing == []
