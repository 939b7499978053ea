"""Text from outside, bounded and inert: where it enters, and where it leaves for a person."""

from __future__ import annotations

import io
import json
import logging

from hypothesis import given
from hypothesis import strategies as st

from frog_bt.codec import encode
from frog_bt.frontend.protocol import MAX_DATAGRAM, encode_datagram
from frog_bt.model.ros import DiagnosticArray, DiagnosticStatus
from frog_bt.text import FIELD, InertFormatter, escape, fit, inert, is_inert

ESCAPES = "\x1b]0;pwned\x07\x1b[31mred\x1b[0m"


def test_controls_and_direction_overrides_are_shown_escaped():
    assert inert(ESCAPES) == "\\x1b]0;pwned\\x07\\x1b[31mred\\x1b[0m"
    assert inert("a\nWARNING frog_bt.alerts: forged") == "a\\nWARNING frog_bt.alerts: forged"
    assert inert("exe.\u202etxt") == "exe.\\u202etxt"  # a right-to-left override
    assert inert("zero\u200bwidth\x85c1") == "zero\\u200bwidth\\x85c1"
    assert inert("Patio de la Montería, ¿sí?") == "Patio de la Montería, ¿sí?"  # words stay


def test_long_text_is_cut_and_the_cut_says_how_much_there_was():
    text = "x" * 9012
    assert inert(text, 40) == "x" * 40 + "… (9,012 bytes)"
    assert inert("é" * 300, 10) == "é" * 10 + "… (600 bytes)"  # bytes, as the wire counts
    assert inert("short", 40) == "short"


@given(st.text())
def test_inert_output_is_bounded_and_inert_for_any_text(text):
    out = inert(text, FIELD)
    assert is_inert(out)
    assert len(out) <= FIELD + len("… (99,999,999 bytes)")
    out.encode("utf-8")  # lone surrogates too come out as text
    assert escape(out) == out  # idempotent where it leaves


def test_a_fault_message_enters_bounded_and_inert():
    status = DiagnosticStatus(2, "motors" + ESCAPES, "Traceback\n" * 1000, "frog")
    (fault,) = DiagnosticArray(status=(status,)).value().faults
    assert is_inert(fault) and fault.endswith("… (10,000 bytes)") and len(fault) < 600


def test_a_datagram_too_long_is_cut_to_fit_never_lost():
    data = encode_datagram("tour", 7, {"state": "aborted", "reason": "y" * 20_000})
    assert len(data) <= MAX_DATAGRAM
    message = json.loads(data)
    assert message["type"] == "tour" and message["seq"] == 7 and message["state"] == "aborted"
    assert message["reason"].endswith("… (20,000 bytes)")


@given(st.dictionaries(st.sampled_from("abcde"), st.text(max_size=5000), max_size=5))
def test_fit_always_fits_and_keeps_every_field(fields):
    out, data = fit(fields, encode, 2048)
    assert len(data) <= 2048 and set(out) == set(fields)


def test_a_log_line_is_one_line_whatever_it_quotes():
    stream = io.StringIO()
    handler = logging.StreamHandler(stream)
    handler.setFormatter(InertFormatter("%(levelname)s %(message)s"))
    logger = logging.getLogger("test_text")
    logger.addHandler(handler)
    try:
        logger.warning("fault: %s", "x\nWARNING frog_bt.alerts: forged" + ESCAPES)
    finally:
        logger.removeHandler(handler)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 1 and "\x1b" not in lines[0] and "\\nWARNING" in lines[0]


def test_words_staff_read_in_the_site_config_are_plain_text(tmp_path):
    import pytest

    from frog_bt.config import load_site
    from frog_bt.errors import ConfigError
    from frog_bt.resources import site_dir

    text = (site_dir() / "site.yaml").read_text()
    bad = tmp_path / "site.yaml"
    bad.write_text(text.replace("names: {es: Tienda}", 'names: {es: "Tienda\\e]0;x\\a"}'))
    with pytest.raises(ConfigError) as caught:
        load_site(bad)
    message = str(caught.value)
    assert "pois.SHOP.names.es: expected a line of plain text" in message
    assert is_inert(message)
