"""Text from outside, made bounded and inert where it enters.

A robot, a front end, a file or a person may send any string: a 9 KB stack trace as a
fault message, terminal escapes that retitle a terminal, a newline that forges a log
line, Unicode direction overrides that reorder what a reader sees. :func:`inert` is the
one rule for such text, applied where it enters (the wires' decoders, the diagnostics,
the front end's fields) and once more where text leaves for a person (the log
formatter, ``ctl``, the status line, the demo summary):

* every control character (C0, DEL, C1), line and paragraph separators and the
  invisible format characters that reorder or hide text (bidi overrides, zero-width
  joiners) are shown escaped (``\\x1b``, ``\\n``, ``\\u202e``), never passed through;
* text longer than ``limit`` characters is cut, and the cut is marked with the size of
  the whole (``… (9,012 bytes)``).

:func:`fit` cuts the string fields of a message until its encoding fits a size limit:
the fields are shortened, the message is never lost.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable
from typing import Any

__all__ = ["FIELD", "LINE", "MESSAGE", "InertFormatter", "escape", "fit", "inert", "is_inert"]

FIELD = 200  # characters: a name, an id, a state word
MESSAGE = 300  # characters: a fault's message, as a reason on a screen or in an alert
LINE = 1000  # characters: a whole reason, a log line's worth of text

# Characters shown escaped: C0 controls, DEL, C1 controls, line/paragraph separators,
# and the format characters that reorder or hide text (bidi embeddings, overrides and
# isolates, zero-width characters, the BOM).
_UNSAFE = re.compile(
    "[\x00-\x1f\x7f-\x9f\u00ad\u061c\u180e\u200b-\u200f\u2028-\u202e\u2060-\u206f\ufeff"
    "\ufff9-\ufffb]"
)
_SIMPLE = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _escape(match: re.Match[str]) -> str:
    char = match.group()
    if char in _SIMPLE:
        return _SIMPLE[char]
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def is_inert(text: str) -> bool:
    """Has ``text`` no character :func:`escape` would escape?"""
    return _UNSAFE.search(text) is None


def escape(text: object) -> str:
    """``text`` (made a string) with every unsafe character shown escaped (lone
    surrogates too); nothing cut. Idempotent: an escape is plain text. What text that
    was already made :func:`inert` gets where it leaves for a person (the log, ``ctl``)."""
    out = text if isinstance(text, str) else str(text)
    if not is_inert(out):
        out = _UNSAFE.sub(_escape, out)
    try:
        out.encode("utf-8")
    except UnicodeEncodeError:
        out = out.encode("utf-8", "backslashreplace").decode("utf-8")
    return out


def inert(text: object, limit: int = FIELD) -> str:
    r"""``text`` :func:`escape`\ d and cut to ``limit`` characters, the cut marked with the
    whole's size in bytes (``… (9,012 bytes)``): what text from outside becomes where it
    enters."""
    whole = text if isinstance(text, str) else str(text)
    out = escape(whole[: limit + 1])
    if len(whole) <= limit and len(out) <= limit:
        return out
    size = len(whole.encode("utf-8", "surrogatepass"))
    return f"{out[:limit]}… ({size:,} bytes)"


def fit(
    fields: dict[str, Any], encode: Callable[[dict[str, Any]], bytes], limit: int
) -> tuple[dict[str, Any], bytes]:
    """``fields`` with their longest strings cut until ``encode`` of them is at most
    ``limit`` bytes; the fields and their encoding. Raises ValueError only when even empty
    strings do not fit (the non-string fields alone are too large)."""
    data = encode(fields)
    if len(data) <= limit:
        return fields, data
    out = dict(fields)
    while len(data) > limit:
        strings = [(len(v), k) for k, v in out.items() if isinstance(v, str) and v]
        if not strings:
            raise ValueError(f"{len(data)} bytes exceed {limit} with no text left to cut")
        length, key = max(strings)
        value: str = out[key]
        excess = len(data) - limit
        keep = max(0, length - excess - 32)
        size = len(value.encode("utf-8", "surrogatepass"))
        out[key] = f"{value[:keep]}… ({size:,} bytes)" if keep else ""
        data = encode(out)
    return out, data


class InertFormatter(logging.Formatter):
    """A log formatter whose lines carry no raw control character: a record's message is
    :func:`escape`\\ d (one record, one line, whatever text it quotes), and so is each
    line of a traceback it carries."""

    def formatMessage(self, record: logging.LogRecord) -> str:
        record.message = escape(record.message)
        return super().formatMessage(record)

    def formatException(self, ei: Any) -> str:
        return "\n".join(escape(line) for line in super().formatException(ei).splitlines())
