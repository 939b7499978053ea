"""Log lines for a journal (syslog priority prefixes) and for log shippers (JSON)."""

from __future__ import annotations

import json
import logging

from frog_bt.commands.logs import JournalFormatter, JsonFormatter


def record(level: int, msg: str) -> logging.LogRecord:
    return logging.LogRecord("frog_bt.alerts", level, __file__, 1, msg, None, None)


def test_journal_lines_carry_their_level_as_a_syslog_prefix() -> None:
    fmt = JournalFormatter("%(levelname)s %(name)s: %(message)s")
    assert fmt.format(record(logging.WARNING, "alert battery_low raised")) == (
        "<4>WARNING frog_bt.alerts: alert battery_low raised"
    )
    # a newline in a message (robot text) never makes a line of its own: it is escaped
    assert fmt.format(record(logging.ERROR, "a\nb\x1b[2J")).splitlines() == [
        "<3>ERROR frog_bt.alerts: a\\nb\\x1b[2J"
    ]


def test_json_lines_are_one_object_each() -> None:
    line = JsonFormatter().format(record(logging.INFO, "operator skip: done"))
    obj = json.loads(line)
    assert "\n" not in line
    assert (obj["level"], obj["logger"], obj["msg"]) == (
        "INFO",
        "frog_bt.alerts",
        "operator skip: done",
    )
