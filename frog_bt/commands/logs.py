"""Logging for a terminal, a journal or a log shipper (``frog-bt run --log-format``).

Every line is one record: a message's control characters are shown escaped
(:class:`~frog_bt.text.InertFormatter`), so robot text never forges a line or moves a
terminal's cursor.

* ``text`` (default): ``LEVEL logger: message``; under systemd (``$JOURNAL_STREAM`` set)
  each line starts with its syslog priority (``<4>`` for a warning), so journald keeps
  the levels (``journalctl -p warning``).
* ``json``: one JSON object per line, ``{"t", "level", "logger", "msg"}`` (and
  ``"exc"`` with a traceback), for log shippers.
"""

from __future__ import annotations

import json
import logging
import os
import sys

from frog_bt.text import InertFormatter, escape

PRIORITY = {
    logging.CRITICAL: 2,
    logging.ERROR: 3,
    logging.WARNING: 4,
    logging.INFO: 6,
    logging.DEBUG: 7,
}  # syslog priorities, as sd-daemon(3) prefixes them


class JournalFormatter(InertFormatter):
    def format(self, record: logging.LogRecord) -> str:
        line = super().format(record)
        prefix = f"<{PRIORITY.get(record.levelno, 6)}>"
        return "\n".join(prefix + part for part in line.splitlines())


class JsonFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        out = {
            "t": round(record.created, 3),
            "level": record.levelname,
            "logger": record.name,
            "msg": escape(record.getMessage()),
        }
        if record.exc_info:
            out["exc"] = self.formatException(record.exc_info)
        return json.dumps(out, ensure_ascii=False)


def setup(verbose: bool = False, fmt: str = "text") -> None:
    handler = logging.StreamHandler(sys.stderr)
    text = "%(levelname)s %(name)s: %(message)s"
    if fmt == "json":
        handler.setFormatter(JsonFormatter())
    elif os.environ.get("JOURNAL_STREAM"):
        handler.setFormatter(JournalFormatter(text))
    else:
        handler.setFormatter(InertFormatter(text))
    root = logging.getLogger()
    for old in list(root.handlers):
        root.removeHandler(old)
    root.addHandler(handler)
    root.setLevel(logging.DEBUG if verbose else logging.WARNING)
