"""The order-aware data-flow check, on the shipped tour and on the mistakes a content
designer makes: each is refused at load time naming the reader, the key and why."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from bench import Bench, write_tree

from frog_bt import resources
from frog_bt.behaviours import FACTORY, load_tree
from frog_bt.config import load_site
from frog_bt.errors import TreeError
from frog_bt.model.key import Key, Scope, Source
from frog_bt.model.outcomes import IncidentKind
from frog_bt.tree import loader
from frog_bt.tree.leaf import FAILURE, SUCCESS, Leaf, Status


@pytest.fixture
def trees(tmp_path: Path) -> Path:
    """An editable copy of the shipped tree files."""
    shutil.copytree(resources.tree_dir(), tmp_path / "trees")
    return tmp_path / "trees"


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new))


def refused(trees: Path) -> str:
    with pytest.raises(TreeError) as info:
        load_tree(trees / "tour.yaml", load_site())
    return re.sub(r"\.yaml:\d+:\d+:", ".yaml:", str(info.value))


def test_the_shipped_tour_passes() -> None:
    load_tree(site=load_site())


def test_removing_seek_visitor_is_refused(trees: Path) -> None:
    edit(trees / "recruit.yaml", "      - {type: SeekVisitor}\n", "")
    message = refused(trees)
    assert "recruit.yaml: root.child.children[0]: ApproachVisitor" in message
    assert "reads /visitor" in message
    assert "not before it on every path" in message  # Checkpointed writes it only after


def test_seek_visitor_after_approach_visitor_is_refused(trees: Path) -> None:
    edit(
        trees / "recruit.yaml",
        "      - {type: SeekVisitor}\n      - {type: ApproachVisitor}\n",
        "      - {type: ApproachVisitor}\n      - {type: SeekVisitor}\n",
    )
    message = refused(trees)
    assert "ApproachVisitor 'ApproachVisitor' reads /visitor" in message
    assert "SeekVisitor 'SeekVisitor' (recruit.yaml:18)" in message


def test_removing_decide_engagement_at_the_stops_is_refused(trees: Path) -> None:
    edit(
        trees / "visit_poi.yaml",
        '                        - {type: DecideEngagement, about: "{poi}", when: face_stream}\n',
        "",
    )
    message = refused(trees)
    assert "visit_poi.yaml" in message and "Engaged 'Engaged' reads /engaged" in message
    assert message.count("\n") == 0  # one error per place, not one per stop


def test_a_value_from_an_earlier_stop_is_not_this_stops(tmp_path: Path) -> None:
    """A decision written before the stops does not reach a stop's reader: each stop of
    a foreach starts without the keys that belong to one stop."""
    (tmp_path / "stop.yaml").write_text("root: {type: Engaged}\n")
    path = write_tree(
        tmp_path,
        """
        root:
          type: Sequence
          memory: true
          children:
            - {type: DecideEngagement, about: introduction}
            - {foreach: stops, include: stop.yaml}
    """,
    )
    with pytest.raises(TreeError, match="a stop starts without it"):
        load_tree(path, load_site())


def test_a_writer_in_another_selector_alternative_does_not_count(tmp_path: Path) -> None:
    path = write_tree(
        tmp_path,
        """
        root:
          type: Selector
          memory: true
          children:
            - {type: SeekVisitor}
            - {type: ApproachVisitor}
    """,
    )
    with pytest.raises(TreeError, match="ApproachVisitor 'ApproachVisitor' reads /visitor"):
        load_tree(path, load_site())


def test_every_error_of_a_tree_in_one_pass(tmp_path: Path) -> None:
    path = write_tree(
        tmp_path,
        """
        root:
          type: Sequence
          memory: true
          children:
            - {type: ApproachVisitor}
            - {type: Engaged}
    """,
    )
    with pytest.raises(TreeError) as info:
        load_tree(path, load_site())
    lines = str(info.value).splitlines()
    assert len(lines) == 2
    assert "children[0]: ApproachVisitor" in lines[0] and "children[1]: Engaged" in lines[1]


def test_a_missing_value_at_run_time_fails_the_leaf_with_a_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Past the check (here switched off), a required read of a value nothing wrote
    fails the reading leaf with the reason; it never raises out of the tick."""
    monkeypatch.setattr(loader, "check_keys", lambda tree: None)
    bench = Bench(write_tree(tmp_path, "root: {type: ApproachVisitor}"))
    assert bench.tick() == FAILURE
    node = bench.node("ApproachVisitor")
    assert node.feedback_message == "no value for /visitor"
    assert [i.kind for i in bench.core.journal.incidents] == [IncidentKind.MISSING_VALUE]


class VisitorName(Leaf):
    """Reads ``/visitor`` declared again, as a name (wrongly: one declaration, an id)."""

    reads = (Key("/visitor", str, Source.LEAF, Scope.TOUR, "the visitor's name"),)

    def update(self) -> Status:
        return SUCCESS


class Mood(Leaf):
    """Reads ``/mood``, which no key declaration knows."""

    reads = (Key("/mood", str, Source.LEAF, Scope.TOUR, "how the visitor feels"),)

    def update(self) -> Status:
        return SUCCESS


@pytest.mark.parametrize(
    ("leaf", "message"),
    [
        (VisitorName, "VisitorName 'VisitorName' uses /visitor, which no key declaration knows"),
        (Mood, "Mood 'Mood' uses /mood, which no key declaration knows"),
    ],
)
def test_keys_are_declared_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, leaf: type[Leaf], message: str
) -> None:
    monkeypatch.setitem(FACTORY.leaves, leaf.__name__, leaf)
    path = write_tree(
        tmp_path,
        f"""
        root:
          type: Sequence
          memory: true
          children:
            - {{type: SeekVisitor}}
            - {{type: {leaf.__name__}}}
    """,
    )
    with pytest.raises(TreeError, match=re.escape(message)):
        load_tree(path, load_site())
