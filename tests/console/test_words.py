"""The words staff read come from the catalogs, and the catalogs are whole: every string
marked in the code, the page and its script has a Spanish translation, the shipped ``.mo``
is the ``.po`` compiled, and translations keep their ``{fields}``."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from frog_bt import i18n
from frog_bt.i18n import Msg, translator
from frog_bt.runtime.phrase import Situation, Step, phrase

babel_messages = pytest.importorskip("babel.messages")
from babel.messages.extract import extract_from_dir  # noqa: E402
from babel.messages.frontend import parse_mapping_cfg  # noqa: E402
from babel.messages.mofile import write_mo  # noqa: E402
from babel.messages.pofile import read_po  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PO = i18n.LOCALE / "es" / "LC_MESSAGES" / "frog_bt.po"
KEYWORDS = {"Msg": None, "N_": None, "t": None}


def marked() -> set[str]:
    """Every string the code, the page and its script mark for the catalogs."""
    with open(i18n.LOCALE / "babel.cfg") as cfg:
        method_map, options_map = parse_mapping_cfg(cfg)
    return {
        message
        for _file, _line, message, _comments, _context in extract_from_dir(
            str(ROOT), method_map, options_map, keywords=KEYWORDS
        )
        if isinstance(message, str) and message
    }


def spanish() -> dict[str, str]:
    with open(PO, "rb") as f:
        return {m.id: m.string for m in read_po(f) if m.id}


def test_every_marked_string_has_a_spanish_translation() -> None:
    missing = sorted(m for m in marked() if not spanish().get(m))
    assert not missing, f"not translated in {PO.name} (pybabel update, then translate): {missing}"


def test_the_page_and_its_script_are_marked() -> None:
    words = marked()
    assert {
        "Send home",
        "Connecting…",
        "Tap again to confirm: {what}",
        "Driving to {stop}",
    } <= words


def test_the_shipped_mo_is_the_po_compiled() -> None:
    with open(PO, "rb") as f:
        catalog = read_po(f)
    compiled = io.BytesIO()
    write_mo(compiled, catalog)
    shipped = PO.with_suffix(".mo").read_bytes()
    assert compiled.getvalue() == shipped, "pybabel compile -d frog_bt/locale -D frog_bt"


def test_translations_keep_their_fields() -> None:
    field = re.compile(r"\{(\w+)\}")
    for msgid, msgstr in spanish().items():
        assert set(field.findall(msgid)) == set(field.findall(msgstr)), msgid


def test_a_sentence_in_both_languages() -> None:
    msg = Msg("Driving to {stop}", stop="Hunting Courtyard")
    assert str(msg) == "Driving to Hunting Courtyard"
    assert msg.say(translator("es")) == "De camino a la parada Hunting Courtyard"
    assert msg.say(translator("es-ES")) == msg.say(translator("es"))
    assert msg.wire() == ["Driving to {stop}", {"stop": "Hunting Courtyard"}]
    assert i18n.catalog("en")["Send home"] == "Send home"
    assert i18n.catalog("es")["Send home"] == "Volver a la base"


@pytest.mark.parametrize(
    ("path", "now", "said"),
    [
        ([Step("Sequence"), Step("SeekVisitor")], Situation(), "Looking for a visitor"),
        ([Step("Navigate", poi="POI2")], Situation(), "Driving to Hunting Courtyard"),
        ([Step("PlayContent", poi="POI1a")], Situation(), "Playing the Almohad wall story"),
        ([Step("Navigate", poi="SHOP")], Situation(), "Driving back to the charger"),
        ([Step("Navigate", poi="POI3")], Situation(going_home=True), "Driving back to the charger"),
        ([Step("Navigate", poi="POI3")], Situation(paused=True), "Paused by staff"),
        (
            [Step("Docking", action="dock")],
            Situation(needs_help=True),
            "Waiting for a person to help",
        ),
        ([Step("Sequence")], Situation(in_service=False), "Out of service, on its charger"),
    ],
)
def test_what_the_robot_is_doing_in_plain_words(
    path: list[Step], now: Situation, said: str
) -> None:
    names = {"POI2": "Hunting Courtyard", "POI1a": "Almohad wall"}
    assert str(phrase(path, now, lambda poi: names.get(poi, poi))) == said
