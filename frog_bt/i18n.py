"""Words for the people on site, in their language: gettext catalogs managed with Babel.

Every sentence staff read (the console page, alerts and what to do, command answers,
``frog-bt ctl``) is written in English in the code, marked for extraction, and translated
through ``frog_bt/locale/<lang>/LC_MESSAGES/frog_bt.po`` (compiled to ``.mo`` beside it,
shipped as package data). English is the source language: it needs no catalog.

* :class:`Msg` is a sentence not yet translated: its English text (the msgid, with
  ``{name}`` fields) and its values. ``str(msg)`` is the English sentence (what is
  recorded and logged); ``msg.say(translator(lang))`` the sentence in ``lang``. A value
  that is itself a :class:`Msg` is translated too.
* :func:`N_` marks a constant for extraction without translating it (a table of words).
* :func:`translator` gives the catalog of one language (cached per process: catalogs are
  read-only data, not state).

Catalogs are kept with Babel (``pybabel extract --no-wrap -F frog_bt/locale/babel.cfg -k Msg
-k N_ -k t -o frog_bt/locale/frog_bt.pot .``, then ``pybabel update --no-wrap`` and ``pybabel
compile -d frog_bt/locale -D frog_bt``: docs/CONSOLE.md, *Languages*);
``tests/console/test_words.py`` fails when a marked string has no Spanish translation or
the ``.mo`` is older than its ``.po``.
"""

from __future__ import annotations

import functools
import gettext
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

DOMAIN = "frog_bt"
LOCALE = Path(__file__).parent / "locale"
LANGUAGES = ("en", "es")  # English first: the source language
SOURCE = "en"


def N_(msgid: str) -> str:
    """Mark ``msgid`` for the catalogs; translated later, where it is shown."""
    return msgid


@dataclass(frozen=True, slots=True)
class Msg:
    """A sentence to be shown to people: English ``msgid`` with ``{field}`` holes, and the
    values that fill them (text, numbers, or further :class:`Msg`)."""

    msgid: str
    args: tuple[tuple[str, Any], ...] = ()

    def __init__(self, msgid: str, /, **args: Any) -> None:
        object.__setattr__(self, "msgid", msgid)
        object.__setattr__(self, "args", tuple(sorted(args.items())))

    def say(self, words: gettext.NullTranslations) -> str:
        values = {k: v.say(words) if isinstance(v, Msg) else v for k, v in self.args}
        text = words.gettext(self.msgid) if self.msgid else ""
        try:
            return text.format(**values)
        except (KeyError, IndexError, ValueError):  # a broken translation: say it in English
            return self.msgid.format(**values)

    def __str__(self) -> str:
        return self.say(_ENGLISH)

    def wire(self) -> list[Any]:
        """As JSON for a page that translates with its own words: ``[msgid, {field:
        value}]``, a :class:`Msg` value nested the same way."""
        return [self.msgid, {k: v.wire() if isinstance(v, Msg) else v for k, v in self.args}]


_ENGLISH = gettext.NullTranslations()


def language(lang: str | None) -> str:
    """``lang`` when there is a catalog for it (``es-ES`` is ``es``), else English."""
    base = (lang or "").strip().lower().replace("_", "-").split("-")[0]
    return base if base in LANGUAGES else SOURCE


@functools.cache
def translator(lang: str | None) -> gettext.NullTranslations:
    """The catalog of ``lang`` (English, the source language, has none)."""
    lang = language(lang)
    if lang == SOURCE:
        return _ENGLISH
    return gettext.translation(DOMAIN, LOCALE, languages=[lang])


def catalog(lang: str | None) -> dict[str, str]:
    """Every msgid of the catalogs and its text in ``lang`` (the page's words)."""
    es = translator("es")
    words = translator(lang)
    ids = [k for k in getattr(es, "_catalog", {}) if isinstance(k, str) and k]
    return {msgid: words.gettext(msgid) for msgid in sorted(ids)}


def say(text: str | Msg, lang: str | None) -> str:
    """``text`` in ``lang``: a :class:`Msg` translated, plain text as it is."""
    return text.say(translator(lang)) if isinstance(text, Msg) else text


_MARKED = re.compile(r'data-w(?:="([^"]*)")?[^>]*>([^<]+)<')


def extract_html(
    fileobj: IO[bytes], keywords: object, comment_tags: object, options: object
) -> Iterator[tuple[int, str, str, list[str]]]:
    """Babel extractor for ``page.html``: the text of every element marked ``data-w`` (the
    page's script translates them in place)."""
    text = fileobj.read().decode("utf-8")
    for match in _MARKED.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        yield line, "", match.group(2).strip(), []
