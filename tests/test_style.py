"""The code base stays clean, and the test command checks it (so CI does too): ruff's lint
and format, the layers (import-linter's contracts in pyproject.toml) and the types (mypy,
strict on model/ and engine/)."""

import ast
import shutil
import subprocess
import sys
from collections.abc import Callable
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


# ------------------------------------------------------------- no cycle hidden by a late import


def _module_name(root: Path, path: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _late(node: ast.AST) -> bool:
    return isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) or (
        isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
    )


Graph = dict[str, dict[str, tuple[int, bool]]]


def _edges(tree: ast.Module, name: str, here: str, resolve: Callable[[str], str | None]):
    """What one module imports of its package: target -> (line, late)."""
    edges: dict[str, tuple[int, bool]] = {}
    todo: list[tuple[ast.AST, bool]] = [(tree, False)]
    while todo:
        node, late = todo.pop()
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = here.split(".")[: len(here.split(".")) - node.level + 1]
                base = ".".join([*up, base] if base else up)
            targets = [f"{base}.{a.name}" for a in node.names] + [base]
        for target in {t for t in map(resolve, targets) if t and t != name}:
            if target not in edges or (edges[target][1] and not late):
                edges[target] = (node.lineno, late)  # type: ignore[attr-defined]
        todo += [(child, late or _late(node)) for child in ast.iter_child_nodes(node)]
    return edges


def import_graph(root: Path, package: str) -> Graph:
    """Each module of ``package`` (under ``root``) -> the package's modules it imports ->
    (line, whether the import is late: inside a function or under ``TYPE_CHECKING``)."""
    modules = {_module_name(root, p): p for p in (root / package).rglob("*.py")}

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    return {
        name: _edges(
            ast.parse(path.read_text()),
            name,
            name if path.name == "__init__.py" else name.rpartition(".")[0],
            resolve,
        )
        for name, path in modules.items()
    }


def hidden_cycles(graph: Graph, known: frozenset[tuple[str, str]] = frozenset()) -> list[str]:
    """Each late import A -> B (but the ``known`` ones) for which B imports A back."""

    def back(start: str, goal: str) -> list[str] | None:
        paths, seen = [[start]], {start}
        while paths:
            path = paths.pop(0)
            for nxt in graph.get(path[-1], {}):
                if nxt == goal:
                    return [*path, nxt]
                if nxt not in seen:
                    seen.add(nxt)
                    paths.append([*path, nxt])
        return None

    found = []
    for a, edges in sorted(graph.items()):
        for b, (line, late) in sorted(edges.items()):
            chain = back(b, a) if late and (a, b) not in known else None
            if chain:
                found.append(f"{a}:{line} imports {b} late, and {' -> '.join(chain)}")
    return found


def test_no_import_inside_a_function_hides_a_cycle():
    """An import inside a function, or under TYPE_CHECKING, hides no file cycle: a module
    of frog_bt that imports another late is not imported back by it (import-linter's
    acyclic contract holds the same over every import)."""
    found = hidden_cycles(import_graph(ROOT, "frog_bt"), frozenset())
    assert not found, "\n".join(found)


def test_the_scan_finds_a_cycle_hidden_in_a_function(tmp_path: Path):
    """The scan sees through a late import: a factory that loads lazily what imports it, a
    module that imports under TYPE_CHECKING what imports it."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "factory.py").write_text("def load():\n    from pkg.loader import load_tree\n")
    (pkg / "loader.py").write_text("from pkg.factory import load\n")
    (pkg / "types.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import loader\n"
    )
    (pkg / "ok.py").write_text("def f():\n    from pkg import types\n")
    (pkg / "host.py").write_text(  # a protocol's module that names its host for the types
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.staff import Staff\n"
    )
    (pkg / "staff.py").write_text("from pkg import host\n")
    found = hidden_cycles(import_graph(tmp_path, "pkg"))
    assert found == [
        "pkg.factory:2 imports pkg.loader late, and pkg.loader -> pkg.factory",
        "pkg.host:3 imports pkg.staff late, and pkg.staff -> pkg.host",
    ]
