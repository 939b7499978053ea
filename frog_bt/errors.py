"""The one exception hierarchy of frog-bt.

::

    FrogError
    ├── DefinitionError          a file the user wrote is wrong; raised before anything connects
    │   ├── ConfigError          config/*.yaml, scenario files
    │   └── TreeError            trees/*.yaml
    ├── UsageError               a command-line value (or a path or address it names) is unusable
    └── DecodeError              one inbound message or datagram is malformed; counted, never fatal

When the tour cannot go on (docking failed, authentication refused) the
executive stops with an exit code and a one-line reason instead (``Outcome``).

Definition errors name the file, the path inside it and what was expected, so a
content designer can fix a YAML file without reading Python.
"""

from __future__ import annotations

from collections.abc import Sequence

from frog_bt.yamlmarks import line_of


class FrogError(Exception):
    """Base class of every error frog-bt raises on purpose."""


def format_path(path: Sequence[str | int]) -> str:
    """``("root", "children", 2, "params")`` -> ``root.children[2].params``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out or "<top>"


class DefinitionError(FrogError):
    """A definition file is invalid: ``file: path: what was expected``."""

    def __init__(
        self,
        file: str,
        path: Sequence[str | int],
        message: str,
        at: tuple[int, int] | None = None,
    ) -> None:
        self.file = str(file)
        self.path = tuple(path)
        self.detail = message
        # (line, column) from 1: ``at`` where the caller knows it (a YAML syntax error),
        # else where ``path`` is written
        self.line = at or (line_of(self.file, self.path) if self.path else None)
        place = f"{self.file}:{self.line[0]}:{self.line[1]}" if self.line else self.file
        where = f"{format_path(self.path)}: " if self.path else ""
        super().__init__(f"{place}: {where}{message}")


class ConfigError(DefinitionError):
    """A site configuration or scenario file is invalid."""


class TreeError(DefinitionError):
    """A tree file is invalid."""


class TreeErrors(TreeError):
    """Several errors of one tree, found in one pass: one line each, in tree order."""

    def __init__(self, errors: Sequence[TreeError]) -> None:
        self.errors = list(errors)
        first = self.errors[0]
        DefinitionError.__init__(self, first.file, first.path, first.detail, first.line)
        self.args = ("\n".join(str(e) for e in self.errors),)

    def __str__(self) -> str:
        return str(self.args[0])


class UsageError(FrogError, ValueError):
    """A command-line value cannot be used: ``OPTION VALUE: what was expected``.

    Raised before the executive runs (a bad URL, an address that cannot be bound, a
    path that cannot be written), so a deployer gets one line and exit code 2.
    """

    def __init__(self, option: str, value: object, message: str) -> None:
        self.option = option
        self.value = value
        self.detail = message
        shown = f" {value}" if value not in (None, "") else ""
        super().__init__(f"{option}{shown}: {message}")


class DecodeError(FrogError):
    """An inbound frame, message or datagram is malformed.

    ``path`` says where in the message the problem is (``msg.pose.position.x``).
    """

    def __init__(self, message: str, path: Sequence[str | int] = ()) -> None:
        self.path = tuple(path)
        self.detail = message
        where = format_path(self.path) if self.path else ""
        super().__init__(f"{where}: {message}" if where else message)


def error_lines(exc: BaseException) -> list[str]:
    """One line per error (several for :class:`TreeErrors`), for a command to print."""
    return [str(e) for e in exc.errors] if isinstance(exc, TreeErrors) else [str(exc)]
