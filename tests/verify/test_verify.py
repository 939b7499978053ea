"""``frog-bt verify``: the shipped tree proves (explored once, tests/verify/conftest.py);
the old service_off shape and mutations of the shipped parts (tests/verify/mutate.py)
each break their property, with the shortest run."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from frog_bt.behaviours import FACTORY
from frog_bt.behaviours.navigation import Navigate
from frog_bt.behaviours.recruit import ApproachVisitor, AskTour
from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.cli import main
from frog_bt.commands import verify as verify_command
from frog_bt.commands.check import VERIFY_STATES
from frog_bt.engine.loaded import LoadedTree
from frog_bt.errors import TreeErrors
from frog_bt.model import keys
from frog_bt.model.frontend import AskTour as AskTourCommand
from frog_bt.tree.factory import NodeFactory
from frog_bt.tree.leaf import RUNNING, SUCCESS, Leaf, Status
from frog_bt.tree.world import Channel, World
from frog_bt.verify import prove as proving
from frog_bt.verify.graph import Run
from frog_bt.verify.properties import BUILT_IN, Broken
from frog_bt.verify.prove import Verdict
from frog_bt.verify.report import finding
from tests.verify.conftest import DATA, Shipped
from tests.verify.mutate import cli, copy, lines, run_of, verdict


def test_the_shipped_tree_holds_every_property(shipped: Shipped) -> None:
    v = shipped.verdict
    assert v.ok, [(b.name, b.run.note) for b in v.broken]
    assert set(BUILT_IN) <= set(v.checked)
    assert len(v.graph.starts) > 1  # the restarts from every checkpoint, explored too
    assert shipped.code == 0, shipped.out + shipped.err
    out = shipped.out
    assert "verified: " in out and "7 properties hold" in out
    # each property's trigger was reached, and how often is said
    counts = dict(re.findall(r"^  ([a-z-]+): triggered by (\d+) ", out, re.MULTILINE))
    assert set(counts) == set(BUILT_IN) and all(int(n) > 0 for n in counts.values())
    assert int(counts["pause-obeyed"]) == v.triggers["pause-obeyed"].count
    assert "states out of service (service_off)" in out


def test_check_proves_as_verify_does(
    shipped: Shipped, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``check`` runs verify's proof on the shipped tour (here the verdict this run
    explored once: check asks for the same tree, with its state limit)."""
    asked: list[tuple[str, dict[str, object]]] = []

    def explored(tree: LoadedTree, site: object, **kwargs: object) -> Verdict:
        asked.append((tree.file, kwargs))
        return shipped.verdict

    monkeypatch.setattr(proving, "prove", explored)
    assert main(["check"]) == 0
    assert capsys.readouterr().out.endswith("; 7 properties hold\n")
    assert asked == [(shipped.verdict.model.tree.file, {"limit": VERIFY_STATES})]


OLD_READY = """            - type: Sequence
              name: Ready to start
              memory: false
              children:
                - {type: WaitInService, name: Wait while out of service}
                - {type: WaitFrontendIdle, name: Wait for the front end}
"""
OLD_SHAPE = """            - {type: WaitInService, name: Wait while out of service}
            - {type: WaitFrontendIdle, name: Wait for the front end}
"""


def test_the_old_service_off_bug_is_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # WaitInService checked once, then WaitFrontendIdle, in "Start a tour" (memory: true)
    tour = copy(tmp_path, {"tour.yaml": [(OLD_READY, OLD_SHAPE)]})
    code, v = cli(monkeypatch, "verify", str(tour), "--format", "mermaid")
    assert code == 1 and v is not None
    assert [b.name for b in v.broken] == ["service-off-obeyed"]
    run = run_of(v, "service-off-obeyed")
    assert lines(v, run) == [  # the front end was idle before the first tick; a fault held
        "front end: frontend_idle; diagnostics: fault; "
        "WaitFrontendIdle 'Wait for the front end' waits for a person or the front end",
        "operator: service_off; [tour started: TourStatus 'TourStatus started']; "
        "[undock sent: Docking 'Docking undock']",
    ]
    out = capsys.readouterr().out
    assert f"{tour}:" in out and ": service-off-obeyed: " in out
    assert "  2. operator: service_off" in out
    assert "flowchart TD" in out and " broke" in out


def test_abort_guard_removed_breaks_home_obeyed(tmp_path: Path) -> None:
    abort = """    - type: Sequence
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
    assert loop == [  # on the way home (a low battery aborted the tour), for ever
        "robot: fails; [Retry 'Go to SHOP' tries again]",
        "[drive goal sent: Navigate 'Navigate SHOP']",
    ]
    assert run.note == "Retry 'Go to SHOP' retries for ever on the robot's own failures"


class NavigateNoPause(Navigate):
    """Navigate with its pause hold taken out (the mutation)."""

    optional_reads = (keys.POSE,)
    waits_while_paused = False


class WaitWhilePaused(Leaf):
    """A pause guard as a leaf: RUNNING while ``/paused``, else SUCCESS."""

    optional_reads = (keys.PAUSED,)
    world = World(inputs=(Channel.OPERATOR,))

    def update(self) -> Status:
        return RUNNING if self.get(keys.PAUSED) else SUCCESS


def test_the_pause_guard_after_the_drive_breaks_pause_obeyed(tmp_path: Path) -> None:
    # pause is modelled from the leaves: one that reads /paused holds its action while
    # paused (Navigate, PlayContent); here the drive ignores it, the guard comes after
    factory = NodeFactory(
        [*(c for c in LEAF_TYPES if c is not Navigate), NavigateNoPause, WaitWhilePaused],
        DECORATOR_TYPES,
    )
    goto = """  child: {type: Navigate, poi: "{poi}"}"""  # in goto.yaml
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
    v = verdict(copy(tmp_path, {"recruit.yaml": [(old, new)]}, recruit=True), factory)
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
    assert "operator: time: Docking dock runs out; [Retry 'Dock' tries again]" in loop  # fails,
    assert any("[Retry 'Home, or ask for help' tries again]" in t for t in loop)  # again
    assert "[drive goal sent: Navigate 'Navigate SHOP']" in loop  # and again
    assert all("AskForHelp" not in t for t in loop)


def test_content_in_parallel_with_a_drive_breaks_no_content_while_driving(
    tmp_path: Path,
) -> None:
    drive = """            - {include: goto.yaml, with: {poi: POI1}}
            - {type: PlayContent, poi: POI1, part: a}
"""
    parallel = """            - type: Parallel
              name: Drive and talk to POI1
              children:
                - {include: goto.yaml, with: {poi: POI1}}
                - {type: PlayContent, poi: POI1, part: a}
"""
    v = verdict(copy(tmp_path, {"tour.yaml": [(drive, parallel)]}))
    run = run_of(v, "no-content-while-driving")
    text = lines(v, run)
    assert "[drive goal sent: Navigate 'Navigate POI1']" in text[-1]
    assert "[content started: PlayContent 'PlayContent POI1 a']" in text[-1]
    assert run.note.endswith("while Navigate 'Navigate POI1' drives")


def test_a_deleted_engagement_decision_is_a_dead_read(tmp_path: Path) -> None:
    decide = "            - {type: DecideEngagement, about: introduction}\n"
    v = verdict(copy(tmp_path, {"recruit.yaml": [(decide, "")]}, recruit=True))
    runs = [b.run for b in v.broken if b.name == "no-dead-reads"]
    assert any(r.note == "AskTour reads /engaged, which no run writes before it" for r in runs)


def test_a_broken_property_is_reported_at_its_node_in_the_included_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``check`` and ``verify`` alike: one ``file:line:column: path: property: what`` line
    at the node (in recruit.yaml, which tour.yaml includes), its shortest run after it
    (verify prints the verdict check explored: one exploration)."""
    decide = "            - {type: DecideEngagement, about: introduction}\n"
    tour = copy(tmp_path, {"recruit.yaml": [(decide, "")]}, recruit=True)
    recruit = tour.with_name("recruit.yaml")
    (line,) = [n for n, text in enumerate(recruit.read_text().splitlines(), 1) if "AskTour" in text]
    column = recruit.read_text().splitlines()[line - 1].index("{type: AskTour}") + 1
    located = (
        f"{recruit}:{line}:{column}: root.child.children[2].child.children[2]: "
        "no-dead-reads: AskTour reads /engaged, which no run writes before it"
    )
    code, v = cli(monkeypatch, "check", str(tour))
    assert code == 2 and v is not None
    err = capsys.readouterr().err.splitlines()
    assert err[0] == located
    assert [e for e in err if not e.startswith("  ")] == [located]  # the run: indented
    assert err[7] == (
        "    5. front end: finish_introduction; [visitor addressed: AskTour]; "
        "WaitAnswer waits for a person or the front end"
    )
    monkeypatch.setattr(verify_command, "prove", lambda tree, site: v)
    assert main(["verify", str(tour)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == located
    assert out[2:4] == [
        "  the shortest run (5 ticks):",
        "    1. front end: frontend_idle; [tour started: TourStatus 'TourStatus started']; "
        "[undock sent: Docking 'Docking undock']",
    ]


def test_designer_properties(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    props = """
properties:
  - {never: [Go to POI1, PlayContent POI1 a], together: true}
  - {between: [TourStatus aborted, TourStatus started], never: Docking undock}
  - {after: Docking undock, within: 1, reaches: PlayContent POI1 a}
"""
    tour = copy(tmp_path, {})
    tour.write_text(tour.read_text() + props)
    v = verdict(tour)
    assert [b.name for b in v.broken] == [
        "after 'Docking undock', within 1 ticks, 'PlayContent POI1 a'"
    ]
    assert v.broken[0].run.note == "'PlayContent POI1 a' not started within 1 ticks"
    tour.write_text(
        tour.read_text() + "  - {never: [No such node, Docking undock], together: true}\n"
    )
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
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A designer's property about a node that never starts, and the built-ins of a tree
    with no tour: each is named vacuous, and verify exits 1."""
    tour = copy(tmp_path, {})
    # ClearAbort ends in the tick it starts: no state has it running
    tour.write_text(
        tour.read_text()
        + "properties:\n  - {never: [ClearAbort, Docking undock], together: true}\n"
    )
    code, v = cli(monkeypatch, "verify", str(tour))
    title = "never 'ClearAbort' and 'Docking undock' together"
    assert v is not None and v.vacuous == [title] and not v.broken and not v.ok
    assert code == 1
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
    assert re.search(
        r"^  service-off-obeyed: triggered by [1-9]\d* states out of service", out, re.M
    )
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
        small=False,
    )
    with pytest.raises(TreeErrors) as raised:
        verdict(tour, factory)  # raised before it explores: the shipped tour is cheap here
    (error,) = raised.value.errors  # one line for the type, though every stop has one
    assert re.fullmatch(
        r".*/visit_poi\.yaml:\d+:\d+: root\..*: leaf type Chime declares no world interface "
        r"for verify \(a `world` World on its class\)",
        str(error),
    ), str(error)


def test_a_finding_about_no_node_is_at_the_root_of_the_tree_file(shipped: Shipped) -> None:
    """A property broken by the tree as a whole (a loop with no node to blame) points at
    the root of the tour file."""
    v = shipped.verdict
    broken = Broken("ends-well", "every tour ends well", Run([], note="loops"))
    first, meaning, *_ = finding(v.model, broken)
    assert re.fullmatch(r".*/tour\.yaml:\d+:\d+: root: ends-well: loops", first), first
    assert meaning == "  ends-well: every tour ends well"


# Here, not in test_coverage.py: the tests that read the shipped tree's exploration are
# in one file, so that -n 2 (whole files per worker) explores it once, not once per worker.


def test_verify_says_which_share_of_the_explored_states_a_season_reached(
    shipped: Shipped,
) -> None:
    line = next(text for text in shipped.out.splitlines() if text.startswith("coverage: "))
    got, explored = (int(n) for n in line.split("reached ")[1].split(" explored")[0].split(" of "))
    assert 10 < got < explored  # one happy tour: many states, far from all
    assert "transitions" in line and "states outside the exploration" not in line


def test_the_suite_s_recordings_and_a_seeded_season_conform(shipped: Shipped) -> None:
    """Every step the recorded tours took (one happy tour, the seeded season with a help
    of each kind and a restart resumed from its checkpoint, the suite's own recording of
    a failed undock) is one the explorer allows, on the same real tree."""
    files = 1 + len(list(shipped.helped.glob("*.mcap"))) + len(list(DATA.glob("*.mcap")))
    assert any(p.name.endswith("-resumed.mcap") for p in shipped.helped.glob("*.mcap"))
    out = shipped.out.splitlines()
    told = f"conformance: {files} of {files} recordings took only steps the explorer allows"
    assert told in out, shipped.out
    assert not [t for t in out if t.endswith("a step the exploration does not allow")]
