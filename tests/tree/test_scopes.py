"""Scopes: an optional read never sees a value left by another scope.

A node that starts a scope (``scope:`` in a tree file, or each stop of a ``foreach``)
clears the keys of that scope and of the narrower ones each time it starts; the
data-flow check refuses a required read that only an earlier scope wrote.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import pytest
from bench import Bench, write_tree

from frog_bt.behaviours import FACTORY, load_tree
from frog_bt.config import load_site
from frog_bt.errors import TreeError
from frog_bt.model import keys
from frog_bt.model.key import Key
from frog_bt.tree.leaf import SUCCESS, Leaf, Status


class WriteEngaged(Leaf):
    """Writes ``/engaged`` = True and ``/skipped`` = POI1. SUCCESS."""

    writes = (keys.ENGAGED, keys.SKIPPED)

    def update(self) -> Status:
        self.set(keys.ENGAGED, True)
        self.set(keys.SKIPPED, "POI1")
        return SUCCESS


class SeeEngaged(Leaf):
    """Reads ``/engaged`` and ``/skipped`` if set, and keeps what it saw. SUCCESS."""

    optional_reads = (keys.ENGAGED, keys.SKIPPED, keys.VISITOR)
    seen: ClassVar[list[tuple[Any, ...]]] = []

    def update(self) -> Status:
        type(self).seen.append(tuple(self.get(k) for k in self.optional_reads))
        return SUCCESS


class NeedEngaged(Leaf):
    """Reads ``/engaged`` (required). SUCCESS."""

    reads = (keys.ENGAGED,)

    def update(self) -> Status:
        return SUCCESS


@pytest.fixture(autouse=True)
def leaves(monkeypatch: pytest.MonkeyPatch) -> None:
    for cls in (WriteEngaged, SeeEngaged, NeedEngaged):
        monkeypatch.setitem(FACTORY.leaves, cls.__name__, cls)
    SeeEngaged.seen = []


def two_parts(scope: str | None) -> str:
    line = f"scope: {scope}, " if scope else ""
    return f"""
    root:
      type: Sequence
      memory: true
      children:
        - {{type: Sequence, {line}memory: true, children: [{{type: WriteEngaged}}]}}
        - {{type: Sequence, {line}memory: true, children: [{{type: SeeEngaged}}]}}
    """


@pytest.mark.parametrize("scope", ["stop", "visitor"])
def test_a_new_scope_clears_what_the_last_one_wrote(tmp_path: Path, scope: str) -> None:
    bench = Bench(write_tree(tmp_path, two_parts(scope)))
    assert bench.tick() == SUCCESS
    assert SeeEngaged.seen == [(None, None, None)]


def test_without_a_scope_the_value_is_seen(tmp_path: Path) -> None:
    bench = Bench(write_tree(tmp_path, two_parts(None)))
    assert bench.tick() == SUCCESS
    assert SeeEngaged.seen == [(True, "POI1", None)]


def test_a_wider_scope_keeps_narrower_scopes_out_but_not_its_own_wider_keys(tmp_path: Path) -> None:
    """A stop does not clear the tour's visitor; a tour clears everything of the tour."""
    bench = Bench(write_tree(tmp_path, two_parts("stop")))
    bench.core.board.set(keys.VISITOR, 7)
    bench.tick()
    assert SeeEngaged.seen == [(None, None, 7)]
    bench2 = Bench(write_tree(tmp_path, two_parts("tour"), "t2.yaml"))
    bench2.core.board.set(keys.VISITOR, 7)
    bench2.tick()
    assert SeeEngaged.seen[-1] == (None, None, None)


def test_each_stop_of_a_foreach_starts_afresh(tmp_path: Path) -> None:
    write_tree(
        tmp_path,
        """
    root:
      type: Sequence
      memory: true
      children: [{type: SeeEngaged}, {type: WriteEngaged}]
    """,
        "stop.yaml",
    )
    bench = Bench(
        write_tree(
            tmp_path,
            """
    root:
      type: Sequence
      memory: true
      children:
        - {foreach: stops, include: stop.yaml}
    """,
        )
    )
    assert bench.tick() == SUCCESS
    stops = len(bench.site.tour.stops)
    assert SeeEngaged.seen == [(None, None, None)] * stops


def test_a_required_read_of_an_earlier_scopes_value_is_refused(tmp_path: Path) -> None:
    path = write_tree(
        tmp_path,
        """
    root:
      type: Sequence
      memory: true
      children:
        - {type: WriteEngaged}
        - {type: Sequence, scope: visitor, memory: true, children: [{type: NeedEngaged}]}
    """,
    )
    with pytest.raises(
        TreeError, match="NeedEngaged 'NeedEngaged' reads /engaged: a visitor starts without it"
    ):
        load_tree(path, load_site())


def test_a_required_read_within_the_scope_is_accepted(tmp_path: Path) -> None:
    path = write_tree(
        tmp_path,
        """
    root:
      type: Sequence
      scope: visitor
      memory: true
      children: [{type: WriteEngaged}, {type: NeedEngaged}]
    """,
    )
    load_tree(path, load_site())


def test_an_unknown_scope_is_a_load_error_naming_the_choices(tmp_path: Path) -> None:
    path = write_tree(
        tmp_path,
        """
    root: {type: Sequence, scope: room, memory: true, children: [{type: SeeEngaged}]}
    """,
    )
    with pytest.raises(
        TreeError,
        match=r"t.yaml:2:\d+: root.scope: .*'tour', 'visitor' or "
        "'stop'",
    ):
        load_tree(path, load_site())


def test_every_key_has_one_declaration() -> None:
    names = [k.name for k in keys.ALL.values()]
    assert len(names) == len(set(names))
    assert all(isinstance(k, Key) and k.doc for k in keys.by_name().values())
