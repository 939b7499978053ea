"""``verify``: the real tree's nodes ticked in a core, only the world abstracted.

A guard deleted from a leaf's own Python code (not from the tree) breaks the property it
served; a leaf that breaks a property only when a tour is resumed is found from the
checkpoints the tree writes; a leaf that keeps state it does not declare is named.
A small tour keeps these fast: the shipped tree is explored once per run
(tests/verify/conftest.py), and its cost is the bench's (scripts/bench_verify.py).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from frog_bt.behaviours import FACTORY
from frog_bt.behaviours.operator import WaitInService
from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.behaviours.visit import PlayContent
from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.errors import TreeErrors
from frog_bt.model import keys
from frog_bt.model.frontend import StartIntroduction
from frog_bt.tree.factory import NodeFactory
from frog_bt.tree.leaf import RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.world import Channel, World, world_of
from frog_bt.verify.prove import Verdict, prove
from frog_bt.verify.report import tick_line

GUARDS = ("pause-obeyed", "service-off-obeyed")
TOUR = """
root:
  type: Selector
  name: FROG
  memory: false
  children:
    - type: Sequence
      name: Abort politely
      memory: true
      children:
        - {type: MustAbort}
        - {type: TourStatus, state: aborted}
        - {type: ClearAbort}
    - type: Sequence
      name: FROG tour
      memory: true
      children:
        - {type: ConfirmResume}
        - {type: WELCOME}
        - type: Checkpointed
          name: Start
          checkpoint: start
          child:
            type: Sequence
            name: Start a tour
            memory: true
            children:
              - type: Sequence
                name: Ready to start
                memory: false
                children:
                  - {type: WAIT, name: Wait while out of service}
                  - {type: WaitFrontendIdle, name: Wait for the front end}
              - {type: TourStatus, state: started}
              - {type: WaitEvent, event: finish_introduction, timeout: 30}
        - type: Checkpointed
          name: Stop
          checkpoint: stop 0
          child: {type: PLAY, poi: POI1}
        - {type: TourStatus, state: ended}
"""


class PlayContentNoPause(PlayContent):
    """PlayContent with its pause check deleted from its code (the mutation)."""

    def initialise(self) -> None:
        self.playing = False
        self.waypoint = self.get(keys.WAYPOINT) or self.params.poi
        self._start()  # whether paused or not


class WaitInServiceNot(WaitInService):
    """WaitInService with its service check deleted (the mutation)."""

    def update(self) -> Status:
        return SUCCESS


class WelcomeBack(Leaf):
    """A resumed tour greets the visitor again, a tick later, without minding the pause;
    a fresh tour goes on at once."""

    optional_reads = (keys.RESUMED,)
    world = World(inputs=(Channel.OPERATOR,), state=("waited",))

    def initialise(self) -> None:
        self.waited = False

    def update(self) -> Status:
        if self.get(keys.RESUMED) is None:
            return SUCCESS
        if not self.waited:
            self.waited = True
            return RUNNING
        self.ctx.send(StartIntroduction(False))
        return SUCCESS


class Quiet(Leaf):
    """Goes on at once: the tour without a greeting."""

    world = World()

    def update(self) -> Status:
        return SUCCESS


class Counting(Leaf):
    """Keeps a count it does not declare."""

    world = World()

    def update(self) -> Status:
        self.count = getattr(self, "count", 0) + 1
        return SUCCESS


class NoWorld(Leaf):
    """Declares no world interface: verify cannot say what it may do."""

    def update(self) -> Status:
        return SUCCESS


FACTORY_ = NodeFactory(
    [*LEAF_TYPES, PlayContentNoPause, WaitInServiceNot, WelcomeBack, Quiet, Counting, NoWorld],
    DECORATOR_TYPES,
)


def tour(
    tmp_path: Path,
    play: str = "PlayContent",
    wait: str = "WaitInService",
    welcome: str = "Quiet",
) -> Path:
    path = tmp_path / "tour.yaml"
    text = TOUR.replace("PLAY", play).replace("WAIT", wait).replace("WELCOME", welcome)
    path.write_text(textwrap.dedent(text))
    return path


def verdict(path: Path, restarts: bool = True) -> Verdict:
    site = load_site(None)
    return prove(FACTORY_.load(path, site), site, properties=[], only=GUARDS, restarts=restarts)


def broken(v: Verdict) -> dict[str, list[str]]:
    return {b.name: [tick_line(v.model, s) for _, s, _ in b.run.ticks] for b in v.broken}


def test_the_real_leaves_hold_their_guards(tmp_path: Path) -> None:
    v = verdict(tour(tmp_path))
    assert v.ok, broken(v)
    assert not v.undeclared and not v.failed
    assert all(v.triggers[name].count > 0 for name in GUARDS)
    assert len(v.graph.starts) > 1  # the checkpoints' restarts were explored too


def test_the_pause_check_deleted_from_play_content_breaks_pause_obeyed(tmp_path: Path) -> None:
    v = verdict(tour(tmp_path, play="PlayContentNoPause"), restarts=False)
    runs = broken(v)
    assert list(runs) == ["pause-obeyed"]
    run = runs["pause-obeyed"]
    assert any("operator: pause" in t for t in run)
    assert "[content started: PlayContentNoPause" in run[-1]
    assert FACTORY.leaves["PlayContent"] is PlayContent  # the tour's factory is untouched


def test_the_service_check_deleted_from_wait_in_service_breaks_service_off(
    tmp_path: Path,
) -> None:
    v = verdict(tour(tmp_path, wait="WaitInServiceNot"), restarts=False)
    runs = broken(v)
    assert list(runs) == ["service-off-obeyed"]
    run = runs["service-off-obeyed"]
    assert any("operator: service_off" in t for t in run)
    assert "[tour started: TourStatus" in run[-1]


def test_a_property_broken_only_on_resume_is_found(tmp_path: Path) -> None:
    path = tour(tmp_path, welcome="WelcomeBack")
    assert verdict(path, restarts=False).ok  # fresh tours never greet again
    v = verdict(path)
    runs = broken(v)
    assert list(runs) == ["pause-obeyed"]
    run = runs["pause-obeyed"]
    assert any("operator: pause" in t for t in run)
    assert "[visitor addressed: WelcomeBack]" in run[-1]
    start = v.broken[0].run.ticks[0][0]
    assert start in v.graph.starts and start != 0  # the run starts from a checkpoint


def test_state_a_leaf_does_not_declare_is_named_by_class(tmp_path: Path) -> None:
    path = tour(tmp_path, welcome="Counting")
    v = verdict(path, restarts=False)
    assert v.undeclared == {"Counting": {"count"}}
    assert not v.ok


def test_verify_on_the_command_line(tmp_path: Path) -> None:
    path = tmp_path / "idle.yaml"
    path.write_text(
        "root:\n  type: Sequence\n  memory: false\n  children:\n"
        "    - {type: WaitInService}\n    - {type: WaitFrontendIdle}\n"
    )
    assert main(["verify", str(path)]) == 1  # vacuous: no tour to pause
    assert main(["verify", "--real", str(path)]) == 1  # --real: accepted, the same


def test_every_registered_node_type_declares_its_world() -> None:
    """verify ticks every node type as it is: each says, on its class, what of the
    world it listens to and what it keeps (frog_bt.tree.world)."""
    types = [*LEAF_TYPES, *DECORATOR_TYPES]
    assert types
    assert [t.__name__ for t in types if world_of(t) is None] == []


def test_a_leaf_without_a_world_or_an_unknown_name_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(TreeErrors) as found:
        verdict(tour(tmp_path, welcome="NoWorld"), restarts=False)
    assert "leaf type NoWorld declares no world interface" in str(found.value.errors[0])
    path = tmp_path / "idle.yaml"
    path.write_text(
        "root:\n  type: Sequence\n  memory: false\n  children:\n"
        "    - {type: WaitInService}\n"
        "properties:\n  - {never: [Nope, WaitInService], together: true}\n"
    )
    assert main(["verify", str(path)]) == 2
