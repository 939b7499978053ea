"""``frog-bt verify``: the shipped tree proves; the old service_off shape and five
mutations of the shipped tree each break their property, with the shortest run."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from frog_bt.behaviours import FACTORY
from frog_bt.behaviours.navigation import Navigate
from frog_bt.behaviours.recruit import ApproachVisitor, AskTour
from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.cli import main
from frog_bt.errors import TreeErrors
from frog_bt.model import keys
from frog_bt.model.frontend import AskTour as AskTourCommand
from frog_bt.tree.factory import NodeFactory
from frog_bt.tree.leaf import RUNNING, SUCCESS, Leaf, Status
from frog_bt.verify.abstraction import Abstraction
from frog_bt.verify.graph import Run
from frog_bt.verify.properties import BUILT_IN, Broken
from frog_bt.verify.report import finding
from frog_bt.verify.world import By, Role
from tests.verify.mutate import copy, lines, run_of, verdict


def test_the_shipped_tree_holds_every_property(capsys: pytest.CaptureFixture[str]) -> None:
    v = verdict(None)
    assert v.ok, [(b.name, b.run.note) for b in v.broken]
    assert set(BUILT_IN) <= set(v.checked)
    assert v.graph.seconds < 30
    assert main(["verify"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("verified: ") and "7 properties hold" in out
    # each property's trigger was reached, and how often is said
    counts = dict(re.findall(r"^  ([a-z-]+): triggered by (\d+) ", out, re.MULTILINE))
    assert set(counts) == set(BUILT_IN) and all(int(n) > 0 for n in counts.values())
    assert int(counts["pause-obeyed"]) == v.triggers["pause-obeyed"].count
    assert "states out of service (service_off)" in out


OLD_READY = """                    - type: Sequence
                      name: Ready to start
                      memory: false        # checked again on every tick: service_off
                      children:            # holds even while the front end is awaited
                        - {type: AskForHelp, about: restored, name: Still waiting for a person}
                        - {type: WaitInService, name: Wait while out of service}
                        - {type: AskForHelp, about: fault, name: Hold while a fault persists}
                        - {type: WaitFrontendIdle, name: Wait for the front end}
"""
OLD_SHAPE = """                    - {type: WaitInService, name: Wait while out of service}
                    - {type: WaitFrontendIdle, name: Wait for the front end}
"""


def test_the_old_service_off_bug_is_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # WaitInService checked once, then WaitFrontendIdle, in "Start a tour" (memory: true)
    tour = copy(tmp_path, {"tour.yaml": [(OLD_READY, OLD_SHAPE)]})
    v = verdict(tour)
    assert [b.name for b in v.broken] == ["service-off-obeyed"]
    run = run_of(v, "service-off-obeyed")
    assert lines(v, run) == [
        "WaitFrontendIdle 'Wait for the front end' running",
        "operator: service_off; WaitFrontendIdle 'Wait for the front end' success; "
        "[tour started: TourStatus 'TourStatus started']; "
        "[undock sent: Docking 'Docking undock']",
    ]
    assert main(["verify", str(tour), "--format", "mermaid"]) == 1
    out = capsys.readouterr().out
    assert f"{tour}:" in out and ": service-off-obeyed: " in out
    assert "  2. operator: service_off" in out
    assert "flowchart TD" in out and " broke" in out


def test_abort_guard_removed_breaks_home_obeyed(tmp_path: Path) -> None:
    abort = """      - type: Sequence
        name: Abort politely
        memory: true
        children:
          - {type: MustAbort}
          - {type: TourStatus, state: aborted}
          - {include: home.yaml}
          - {type: ClearAbort}
"""
    v = verdict(copy(tmp_path, {"tour.yaml": [(abort, "")]}))
    run = run_of(v, "home-obeyed")
    text = lines(v, run)
    assert any("operator: home" in t for t in text)
    assert "[content started: PlayContent 'PlayContent POI1 a" in text[-1]
    assert run.note == "content started after home"


def test_a_retry_bound_removed_breaks_bounded_retries(tmp_path: Path) -> None:
    tour = copy(tmp_path, {"goto.yaml": [('attempts: "{nav_attempts}"', "attempts: null")]})
    v = verdict(tour)
    run = run_of(v, "bounded-retries")
    assert run.loop_from is not None
    loop = lines(v, run)[run.loop_from :]
    assert all("Guide a visitor" not in t for t in loop)
    assert any(
        "Navigate 'Navigate POI0' failure; [Retry 'Go to POI0' tries again]" in t for t in loop
    )
    assert run.note == "Retry 'Go to POI0' retries for ever on the robot's own failures"


class NavigateNoPause(Navigate):
    """Navigate with its pause hold taken out (the mutation)."""

    optional_reads = (keys.POSE,)
    waits_while_paused = False


class WaitWhilePaused(Leaf):
    """A pause guard as a leaf: RUNNING while ``/paused``, else SUCCESS."""

    optional_reads = (keys.PAUSED,)
    verify = Abstraction(role=Role.NONE, rule=lambda t, n, aux, starting: _paused(t, n))

    def update(self) -> Status:
        return RUNNING if self.get(keys.PAUSED) else SUCCESS


def _paused(t: object, n: object) -> tuple[int, int]:
    from frog_bt.verify.world import PAUSED
    from frog_bt.verify.world import RUNNING as R
    from frog_bt.verify.world import SUCCESS as S

    if t.world[PAUSED]:  # type: ignore[attr-defined]
        t.waits(n, By.WORLD, "paused")  # type: ignore[attr-defined]
        return R, 0
    return S, 0


def test_the_pause_guard_after_the_drive_breaks_pause_obeyed(tmp_path: Path) -> None:
    # pause is modelled from the leaves: one that reads /paused holds its action while
    # paused (Navigate, PlayContent); here the drive ignores it, the guard comes after
    factory = NodeFactory(
        [*(c for c in LEAF_TYPES if c is not Navigate), NavigateNoPause, WaitWhilePaused],
        DECORATOR_TYPES,
    )
    goto = """  child: {type: Navigate, poi: "{poi}"}"""
    moved = """  child:
    type: Sequence
    name: "Drive to {poi}, then mind the pause"
    memory: true
    children:
      - {type: NavigateNoPause, poi: "{poi}"}
      - {type: WaitWhilePaused}"""
    v = verdict(copy(tmp_path, {"goto.yaml": [(goto, moved)]}), factory)
    run = run_of(v, "pause-obeyed")
    text = lines(v, run)
    assert any("operator: pause" in t for t in text)
    assert "[drive goal sent: NavigateNoPause" in text[-1]
    assert run.note == "drive goal sent while paused"
    assert FACTORY.leaves["Navigate"] is Navigate  # the tour's factory is untouched


class AskTourNoPause(AskTour):
    """AskTour as it was: it asked the visitor whether paused or not (the mutation)."""

    optional_reads = (keys.ENGAGED,)

    def update(self) -> Status:
        self.ctx.send(AskTourCommand(self.get(keys.ENGAGED)))
        return SUCCESS


class ApproachNoPause(ApproachVisitor):
    """ApproachVisitor as it was: the approach went out while paused (the mutation)."""

    optional_reads = (keys.APPROACH_FAILED,)
    waits_while_paused = False


@pytest.mark.parametrize(
    ("old", "new", "cls", "note"),
    [
        ("{type: AskTour}", "{type: AskTourNoPause}", AskTour, "visitor addressed while paused"),
        (
            "{type: ApproachVisitor}",
            "{type: ApproachNoPause}",
            ApproachVisitor,
            "approach sent while paused",
        ),
    ],
)
def test_a_recruiting_leaf_that_ignores_the_pause_breaks_pause_obeyed(
    tmp_path: Path, old: str, new: str, cls: type, note: str
) -> None:
    """CONTRACT §7: no new goal and no new content until resume, the approach and the
    question to the visitor too."""
    factory = NodeFactory([*LEAF_TYPES, AskTourNoPause, ApproachNoPause], DECORATOR_TYPES)
    v = verdict(copy(tmp_path, {"recruit.yaml": [(old, new)]}), factory)
    run = run_of(v, "pause-obeyed")
    assert any("operator: pause" in t for t in lines(v, run))
    assert run.note == note
    assert FACTORY.leaves[cls.__name__] is cls  # the tour's factory is untouched


def test_the_dock_failure_branch_made_to_loop_breaks_ends_well(tmp_path: Path) -> None:
    tour = copy(tmp_path, {"home.yaml": [("      - {type: AskForHelp, about: home}\n", "")]})
    v = verdict(tour)
    run = run_of(v, "ends-well")
    assert run.loop_from is not None
    loop = lines(v, run)[run.loop_from :]
    assert any("Navigate 'Navigate SHOP' failure" in t for t in loop)  # the way home fails,
    assert any("[Retry 'Home, or ask for help' tries again]" in t for t in loop)  # again
    assert all("AskForHelp" not in t for t in loop)


def test_content_in_parallel_with_a_drive_breaks_no_content_while_driving(
    tmp_path: Path,
) -> None:
    drive = """                child: {include: goto.yaml}"""
    parallel = """                child:
                  type: Parallel
                  name: "Drive and talk to {poi}"
                  children:
                    - {include: goto.yaml}
                    - {type: PlayContent, poi: "{poi}", part: a}"""
    v = verdict(copy(tmp_path, {"visit_poi.yaml": [(drive, parallel)]}))
    run = run_of(v, "no-content-while-driving")
    text = lines(v, run)
    assert "[drive goal sent: Navigate 'Navigate POI1']" in text[-1]
    assert "[content started: PlayContent 'PlayContent POI1 a']" in text[-1]
    assert run.note.endswith("while Navigate 'Navigate POI1' drives")


def test_a_deleted_engagement_decision_is_a_dead_read(tmp_path: Path) -> None:
    decide = "            - {type: DecideEngagement, about: introduction}\n"
    v = verdict(copy(tmp_path, {"recruit.yaml": [(decide, "")]}))
    runs = [b.run for b in v.broken if b.name == "no-dead-reads"]
    assert any(r.note == "AskTour reads /engaged, which no run writes before it" for r in runs)


def test_a_broken_property_is_reported_at_its_node_in_the_included_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check`` and ``verify`` alike: one ``file:line:column: path: property: what`` line
    at the node (in recruit.yaml, which tour.yaml includes), its shortest run after it."""
    decide = "            - {type: DecideEngagement, about: introduction}\n"
    tour = copy(tmp_path, {"recruit.yaml": [(decide, "")]})
    recruit = tour.with_name("recruit.yaml")
    (line,) = [n for n, text in enumerate(recruit.read_text().splitlines(), 1) if "AskTour" in text]
    column = recruit.read_text().splitlines()[line - 1].index("{type: AskTour}") + 1
    located = (
        f"{recruit}:{line}:{column}: root.child.children[2].child.children[2]: "
        "no-dead-reads: AskTour reads /engaged, which no run writes before it"
    )
    assert main(["check", str(tour)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == located
    assert [e for e in err if not e.startswith("  ")] == [located]  # the run: indented
    assert "    5. [visitor addressed: AskTour]" in err
    assert main(["verify", str(tour)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == located
    assert out[2:4] == [
        "  the shortest run (5 ticks):",
        "    1. WaitFrontendIdle 'Wait for the front end' success; "
        "[tour started: TourStatus 'TourStatus started']; "
        "[undock sent: Docking 'Docking undock']",
    ]


def test_designer_properties(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    props = """
properties:
  - {never: [Guide to POI1, Present POI1], together: true}
  - {between: [TourStatus aborted, TourStatus started], never: Docking undock}
  - {after: Docking undock, within: 1, reaches: Go to POI0}
"""
    tour = copy(tmp_path, {})
    tour.write_text(tour.read_text() + props)
    v = verdict(tour)
    assert [b.name for b in v.broken] == ["after 'Docking undock', within 1 ticks, 'Go to POI0'"]
    assert v.broken[0].run.note == "'Go to POI0' not started within 1 ticks"
    tour.write_text(tour.read_text() + "  - {never: [No such node, Undock], together: true}\n")
    assert main(["check", str(tour)]) == 2
    assert "no node named 'No such node' in the tree" in capsys.readouterr().err
    # verify as check: exit 2, one line per unknown name, at the property
    assert main(["verify", str(tour)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1, err
    assert re.fullmatch(
        rf"{re.escape(str(tour))}:\d+:\d+: properties\[3\]: no node named 'No such node' in "
        "the tree",
        err[0],
    )


def test_a_property_whose_trigger_no_run_reaches_is_vacuous(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A designer's property about a node that never starts, and the built-ins of a tree
    with no tour: each is named vacuous, and verify exits 1."""
    tour = copy(tmp_path, {})
    # ClearAbort ends in the tick it starts: no state has it running
    tour.write_text(
        tour.read_text()
        + "properties:\n  - {never: [ClearAbort, Docking undock], together: true}\n"
    )
    v = verdict(tour)
    title = "never 'ClearAbort' and 'Docking undock' together"
    assert v.vacuous == [title] and not v.broken and not v.ok
    assert main(["verify", str(tour)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert re.fullmatch(
        rf".*/tour\.yaml:\d+:\d+: root\..*: {re.escape(title)}: vacuous: no run reaches its "
        r"trigger \(0 states in which 'ClearAbort' runs\), .*",
        out[0],
    ), out[0]
    assert out[1] == "0 properties broken, 1 vacuous, 7 hold (" + out[1].split("(")[1]

    idle = tmp_path / "idle.yaml"
    idle.write_text(
        "root:\n  type: Sequence\n  memory: false\n  children:\n"
        "    - {type: WaitInService}\n    - {type: WaitFrontendIdle}\n"
    )
    assert main(["verify", str(idle)]) == 1
    out = capsys.readouterr().out
    assert f"{idle}:2:3: root: pause-obeyed: vacuous: no run reaches its trigger (0 states " in out
    assert "  service-off-obeyed: triggered by 1 states out of service" in out
    assert main(["check", str(idle)]) == 2
    assert ": root: bounded-retries: vacuous: " in capsys.readouterr().err


INDENT = " " * 24  # of the leaves of a stop's content, in visit_poi.yaml
FINISH = f"{INDENT}- {{type: FinishPoi"


class Chime(Leaf):
    """A leaf verify knows nothing about: no world interface declared."""

    def update(self) -> Status:
        return SUCCESS


def test_a_leaf_type_without_a_world_interface_is_an_error(tmp_path: Path) -> None:
    factory = NodeFactory([*LEAF_TYPES, Chime], DECORATOR_TYPES)
    tour = copy(
        tmp_path,
        {
            "visit_poi.yaml": [
                (
                    f"{INDENT}- {{type: FinishPoi",
                    f"{INDENT}- {{type: Chime}}\n{INDENT}- {{type: FinishPoi",
                )
            ]
        },
    )
    with pytest.raises(TreeErrors) as raised:
        verdict(tour, factory)
    (error,) = raised.value.errors  # one line for the type, though every stop has one
    assert re.fullmatch(
        r".*/visit_poi\.yaml:\d+:\d+: root\..*: leaf type Chime declares no world interface "
        r"for verify \(a `verify` Abstraction on its class\)",
        str(error),
    ), str(error)


def test_a_finding_about_no_node_is_at_the_root_of_the_tree_file() -> None:
    """A property broken by the tree as a whole (a loop with no node to blame) points at
    the root of the tour file."""
    v = verdict(None)
    broken = Broken("ends-well", "every tour ends well", Run([], note="loops"))
    first, meaning, *_ = finding(v.model, broken)
    assert re.fullmatch(r".*/tour\.yaml:\d+:\d+: root: ends-well: loops", first), first
    assert meaning == "  ends-well: every tour ends well"
