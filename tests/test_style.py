"""The code base stays clean, and the test command checks it (so CI does too): ruff's lint
and format, the layers (import-linter's contracts in pyproject.toml) and the types (mypy,
strict on model/ and engine/)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PATHS = [p for p in ("frog_bt", "tests", "scripts") if (ROOT / p).exists()]


def tool(name: str) -> str:
    found = shutil.which(name, path=str(Path(sys.executable).parent)) or shutil.which(name)
    if found is None:
        pytest.fail(f"{name} is not installed: pip install -e '.[test]'")
    return found


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(args, cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_ruff_is_clean():
    result = run(tool("ruff"), "check", "--no-cache", *PATHS)
    assert result.returncode == 0, result.stdout + result.stderr


def test_ruff_format_is_applied():
    result = run(tool("ruff"), "format", "--check", "--no-cache", *PATHS)
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_layers_hold_no_cycle_and_no_upward_import():
    """Each layer imports only those below it (pyproject.toml's [tool.importlinter])."""
    result = run(tool("lint-imports"), "--no-cache")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Contracts: " in result.stdout and " broken" in result.stdout
    assert " 0 broken" in result.stdout, result.stdout


def test_mypy_is_clean():
    """pyproject.toml's [tool.mypy]: the whole package, strict on model/ and engine/."""
    result = run(tool("mypy"), "frog_bt")
    assert result.returncode == 0, result.stdout + result.stderr
