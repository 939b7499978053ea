"""Where each path of a YAML file is written (line, column), for errors that point at it.

The bottom of the package: :mod:`frog_bt.errors` reads it to place a definition error.
"""

from __future__ import annotations

from pathlib import Path

import yaml

__all__ = ["Marks", "line_of", "mark_paths"]

Marks = dict[tuple[str | int, ...], tuple[int, int]]  # path in a file -> (line, column)


def mark_paths(
    node: yaml.Node, path: tuple[str | int, ...], out: dict[tuple[str | int, ...], tuple[int, int]]
) -> None:
    out[path] = (node.start_mark.line + 1, node.start_mark.column + 1)
    if isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            if isinstance(key, yaml.ScalarNode):
                mark_paths(value, (*path, key.value), out)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            mark_paths(item, (*path, i), out)


def line_of(
    file: str, path: tuple[str | int, ...], marks: Marks | None = None
) -> tuple[int, int] | None:
    """(line, column) of ``path`` in ``file``, or of its nearest ancestor there: from
    ``marks`` when given, else the file is read again (errors only: nothing is kept)."""
    if marks is None:
        try:
            node = yaml.compose(Path(file).read_text(encoding="utf-8"), Loader=yaml.SafeLoader)
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            return None
        marks = {}
        if node is not None:
            mark_paths(node, (), marks)
    if not marks:
        return None
    for n in range(len(path), -1, -1):
        found = marks.get(tuple(path[:n]))
        if found is not None:
            return found
    return None
