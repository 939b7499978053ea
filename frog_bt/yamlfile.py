"""Loading YAML definition files safely, with errors that name file and path.

Every definition file (site config, trees, scenarios) goes through
:func:`load_yaml` (``yaml.safe_load``: no Python objects can be built from a
file) and, when it has a pydantic model, through :func:`validate`, which turns
pydantic's errors into one :class:`~frog_bt.errors.DefinitionError` naming the
file, the path in it and what was expected.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from frog_bt.errors import DefinitionError
from frog_bt.yamlmarks import Marks, mark_paths

M = TypeVar("M", bound=BaseModel)


def load_yaml(path: str | Path, error: type[DefinitionError]) -> Any:
    return load_yaml_marked(path, error)[0]


def load_yaml_marked(path: str | Path, error: type[DefinitionError]) -> tuple[Any, Marks]:
    """The file's data, and where each path in it is written (line, column from 1)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise error(str(path), (), f"cannot read: {exc.strerror or exc}") from exc
    try:
        node, data = _parse(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = (mark.line + 1, mark.column + 1) if mark else None  # file:line:col: as check's
        problem = getattr(exc, "problem", None) or str(exc)
        raise error(str(path), (), f"not valid YAML: {problem}", at) from exc
    marks: Marks = {}
    if node is not None:
        mark_paths(node, (), marks)
    return data, marks


# libyaml's parser where installed (ten times faster than the pure-Python one: start-up
# reads the site config and the tree files), with the same safe constructor.
_FAST: type[Any] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _parse(text: str) -> tuple[Any, Any]:
    """The document's node (its marks) and its data, from one parse. A file that does not
    parse is parsed again by the pure-Python loader, whose error messages are the ones
    people have seen (libyaml words some of them differently)."""
    try:
        loader = _FAST(text)
        try:
            node = loader.get_single_node()
            return node, (loader.construct_document(node) if node is not None else None)
        finally:
            loader.dispose()
    except yaml.YAMLError:
        if _FAST is yaml.SafeLoader:
            raise
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        return node, (loader.construct_document(node) if node is not None else None)
    finally:
        loader.dispose()


class PathError(ValueError):
    """Raised by a model validator to point at a path below the model being validated."""

    def __init__(self, path: tuple[str | int, ...], message: str) -> None:
        super().__init__(message)
        self.path = path


def validate(
    model: type[M],
    data: Any,
    file: str | Path,
    error: type[DefinitionError],
    context: dict[str, Any] | None = None,
    base: tuple[str | int, ...] = (),
) -> M:
    """``model`` validated from ``data``; the first error becomes a DefinitionError.

    ``base`` is the path of ``data`` inside the file.
    """
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        first = exc.errors(include_url=False)[0]
        loc = tuple(p for p in first["loc"] if not _is_union_tag(p))
        message = first["msg"]
        cause = first.get("ctx", {}).get("error")
        if isinstance(cause, PathError):
            loc, message = (*loc, *cause.path), str(cause)
        elif isinstance(cause, ValueError):
            message = str(cause)
        elif first["type"] == "extra_forbidden":
            message = "unknown key"
        elif first["type"] == "missing":
            message = "missing required key"
        elif "input" in first and first["type"] not in ("value_error", "assertion_error"):
            message = f"{message}, got {_short(first['input'])}"
        raise error(str(file), (*base, *loc), message) from None


def _is_union_tag(part: Any) -> bool:
    # pydantic inserts the member type name into loc for unions (e.g. 'function-after[...]').
    return isinstance(part, str) and ("[" in part or part in ("int", "float", "str", "bool"))


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
