"""``frog-bt render``: golden outputs, Graphviz images, one-line errors, no network stack.

Golden files are in ``golden/`` beside this file: ``tour.*`` is the shipped tour
(``trees/tour.yaml`` with ``config/site.yaml``), ``small_keys.*`` the hand-written
``trees/small.yaml`` here, drawn with ``--keys``. After an intended change to a
tree, a leaf's parameters or keys, or the renderer, regenerate them and review
the diff::

    FROG_UPDATE_GOLDEN=1 .venv/bin/pytest tests/render

Tests that need Graphviz's ``dot`` skip when it is not installed.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.tree import render

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
GOLDEN = HERE / "golden"
SMALL = HERE / "trees" / "small.yaml"
needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz `dot` not installed")


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["render", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def check_golden(name: str, actual: str) -> None:
    path = GOLDEN / name
    if os.environ.get("FROG_UPDATE_GOLDEN"):
        path.write_text(actual, encoding="utf-8")
        return
    assert path.exists(), f"{path.name} missing: run with FROG_UPDATE_GOLDEN=1"
    assert actual == path.read_text(encoding="utf-8"), (
        f"{path.name} differs; if intended, regenerate with FROG_UPDATE_GOLDEN=1"
    )


@pytest.mark.parametrize(
    ("golden", "argv"),
    [
        ("tour.ascii.txt", []),
        ("tour.unicode.txt", ["--format", "unicode"]),
        ("tour.dot", ["--format", "dot"]),
        ("tour.mmd", ["--format", "mermaid"]),
        ("small_keys.ascii.txt", [str(SMALL), "--keys"]),
        ("small_keys.unicode.txt", [str(SMALL), "--keys", "-f", "unicode"]),
        ("small_keys.dot", [str(SMALL), "--keys", "-f", "dot"]),
        ("small_keys.mmd", [str(SMALL), "--keys", "-f", "mermaid"]),
    ],
)
def test_text_formats_match_their_golden_files(capsys, golden, argv):
    code, out, err = cli(capsys, *argv)
    assert (code, err) == (0, "")
    check_golden(golden, out)


def test_output_is_deterministic_and_numbers_every_node_in_pre_order():
    tree = load_tree(SMALL)
    first, second = render.outline(tree.root), render.outline(load_tree(SMALL).root)
    assert render.dot(first) == render.dot(second)
    assert [n.id for n in first.walk()] == [f"n{i}" for i in range(len(list(tree.nodes())))]


def test_output_file_gets_what_stdout_would(capsys, tmp_path):
    target = tmp_path / "tree.mmd"
    assert cli(capsys, "-f", "mermaid", "-o", str(target)) == (0, "", "")
    assert target.read_text(encoding="utf-8") == cli(capsys, "-f", "mermaid")[1]


def test_labels_are_escaped_for_dot_and_mermaid():
    small = render.outline(load_tree(SMALL).root)
    dot_text, mermaid_text = render.dot(small), render.mermaid(small)
    assert r'label="Wait\\for \"done\"\nWaitEvent' in dot_text
    assert (
        '"→ Greet #quot;visitor#quot; [#35;1] #lt;now#gt; #amp; #96;then#96;<br/>' in mermaid_text
    )
    labels = [
        line.split('"', 1)[1].rsplit('"', 1)[0].replace("<br/>", "\n")
        for line in mermaid_text.splitlines()
        if line.startswith("    n") and '"' in line
    ]
    assert labels and not any(c in label for label in labels for c in '"<>`')


@needs_dot
@pytest.mark.parametrize("tree", [None, SMALL])
def test_dot_output_is_accepted_by_graphviz(tree):
    root = render.outline(load_tree(tree).root)
    assert b"<svg" in render.graphviz(render.dot(root, keys=True), "svg")


@needs_dot
@pytest.mark.parametrize(("fmt", "magic"), [("svg", b"<?xml"), ("png", b"\x89PNG\r\n\x1a\n")])
def test_images_are_written_with_dot(capsys, tmp_path, fmt, magic):
    target = tmp_path / f"tour.{fmt}"
    assert cli(capsys, "-f", fmt, "--rankdir", "LR", "-o", str(target)) == (0, "", "")
    assert target.read_bytes().startswith(magic)


@pytest.mark.parametrize("fmt", ["svg", "png"])
def test_images_without_dot_exit_1_with_one_line(capsys, monkeypatch, tmp_path, fmt):
    monkeypatch.setenv("PATH", str(tmp_path))  # an empty folder: no `dot` anywhere
    code, out, err = cli(capsys, "-f", fmt, "-o", str(tmp_path / f"tree.{fmt}"))
    assert (code, out) == (1, "")
    assert err == (
        f"frog-bt: {fmt} needs Graphviz's `dot` program, which is not installed "
        "(apt-get install graphviz)\n"
    )
    assert not (tmp_path / f"tree.{fmt}").exists()


def test_an_invalid_tree_exits_2_naming_file_and_path(capsys, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("root: {type: Sequence, children: [{type: FinishPoi, poi: POI1}]}\n")
    code, out, err = cli(capsys, str(bad), "-f", "dot")
    assert (code, out) == (2, "")
    assert err == (
        f"frog-bt: {bad}:1:7: root.memory: missing required key: "
        "a Sequence must say memory: true or false\n"
    )


def test_an_invalid_config_exits_2(capsys, tmp_path):
    bad = tmp_path / "site.yaml"
    bad.write_text("pois: []\n")
    code, out, err = cli(capsys, "--config", str(bad))
    assert (code, out) == (2, "")
    assert err.startswith(f"frog-bt: {bad}:1:7: pois: ") and err.count("\n") == 1


def test_render_loads_neither_websockets_nor_rerun(tmp_path):
    code = textwrap.dedent(f"""
        import sys
        from frog_bt.commands import render
        from frog_bt.cli import main
        from frog_bt.tree.render import outline
        from frog_bt.behaviours import load_tree
        root = outline(load_tree().root)
        for fmt in ("ascii", "unicode", "dot", "mermaid"):
            assert render.draw(root, fmt, keys=True)
        assert main(["render", "--keys", "-o", {str(tmp_path / "tree.txt")!r}]) == 0
        loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("websockets", "rerun"))
        assert not loaded, loaded
    """)
    result = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
