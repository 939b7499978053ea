"""``frog-bt coverage``: a seeded recording replayed, its nodes counted, the never-run
ones marked; ``verify --coverage`` and ``--conformance``: recordings against the real
tree's exploration."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from frog_bt.behaviours import tour
from frog_bt.behaviours.registry import DECORATOR_TYPES, LEAF_TYPES
from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.offline.conformance import conformance
from frog_bt.tree.factory import NodeFactory
from frog_bt.verify.prove import prove


def test_coverage_of_a_recorded_tour(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], one_tour: Path
) -> None:
    (tmp_path / "season").mkdir()
    (tmp_path / "season" / "tour.mcap").write_bytes(one_tour.read_bytes())
    page = tmp_path / "coverage.html"
    assert main(["coverage", str(tmp_path / "season"), "-o", str(page)]) == 0
    out = capsys.readouterr().out.splitlines()
    line = {text.strip().split(":")[0]: text for text in out}
    # what the tour did ran...
    assert "ran 1x: succeeded 1" in line["Docking 'Docking undock'"]
    assert "succeeded 1" in line["Navigate 'Navigate POI1'"]
    # ...and what nothing in it called for never did
    assert "failed" in line["Sequence 'Abort politely'"]  # its guard fails every tick
    assert line["ClearAbort"].endswith("never run")
    assert line["SkipStop 'SkipStop POI1'"].endswith("never run")
    assert line["AskForHelp 'AskForHelp undock'"].endswith("never run")
    assert out[-2].startswith("1 recordings: ") and "never ran" in out[-2]
    # every outcome shown is one the key under the tree explains, and their counts add
    # up to the runs (a node halted while running is "stopped", never a bare "invalid")
    key = " ".join(out[out.index(next(t for t in out if t.startswith("ran Nx: "))) : -3])
    shown: set[str] = set()
    for text in out:
        if ": ran " in text:
            runs = int(text.split(": ran ")[1].split("x")[0])
            ends = text.split("x: ", 1)[1].split(", ")
            shown.update(e.rsplit(" ", 1)[0] for e in ends)
            assert sum(int(e.rsplit(" ", 1)[1]) for e in ends) == runs, text
    assert shown >= {"succeeded", "failed"}, shown
    assert all(f"{word} (" in key for word in shown), (shown, key)
    assert "invalid" not in "\n".join(out).lower()
    # the tour, as the one count of tours (and the report) has it
    assert out[-3] == "tours: 1 (1 ended, 0 aborted); stops reached 6, played 6, skipped 0"
    html = page.read_text()
    assert "stopped (halted while running" in html
    assert '<tr class="never"><td style="padding-left:3em">ClearAbort</td>' in html
    assert "<script" not in html
    # the same counts through the Executor seam (two worker processes, two copies)
    (tmp_path / "season" / "copy.mcap").write_bytes(one_tour.read_bytes())
    assert main(["coverage", str(tmp_path / "season"), "--jobs", "2"]) == 0
    doubled = capsys.readouterr().out.splitlines()
    assert doubled[-1].startswith("2 recordings: ")
    twice = {text.strip().split(":")[0]: text for text in doubled}
    assert "ran 2x: succeeded 2" in twice["Docking 'Docking undock'"]


class WaitFrontendIdle(tour.WaitFrontendIdle):
    """WaitFrontendIdle as a wrong world model has it: the front end never says it is
    idle (its code is the real one; only what the explorer may send it is wrong)."""

    world = dataclasses.replace(tour.WaitFrontendIdle.world, frontend=lambda n: ())


def test_a_recording_the_world_model_does_not_allow_is_named(one_tour: Path) -> None:
    """The happy tour, checked against the exploration of a world whose front end never
    says it is ready: the first step the robot took outside it is named, with its tick
    and node (the explorer never let the tour start)."""
    factory = NodeFactory(
        [*(c for c in LEAF_TYPES if c.__name__ != "WaitFrontendIdle"), WaitFrontendIdle],
        DECORATOR_TYPES,
    )
    site = load_site(None)
    v = prove(factory.load(None, site), site, restarts=False)
    files, outside = conformance(
        v.graph,
        v.model,
        site,
        lambda: factory.load(None, site),
        [one_tour],
        lambda path, why: pytest.fail(why),
    )
    assert files == 1
    (step,) = outside
    assert step.recording == one_tour and step.tick >= 1
    # the first node running that the exploration never ran: the tour's undock
    assert (step.node, step.what) == ("Retry 'Undock, or ask for help'", "running")
    assert step.line() == (
        f"{one_tour}: tick {step.tick}: {step.node} running: a step the exploration does not allow"
    )


def test_every_outcome_coverage_shows_is_in_its_key() -> None:
    """A run halted while running is "stopped", one a recording ended in is "still
    running"; the key printed under the tree says what each word means."""
    from collections import Counter

    from frog_bt.verify.coverage import KEY, NodeCount, outcomes

    count = NodeCount(runs=5, outcomes=Counter({"SUCCESS": 2, "FAILURE": 1, "INVALID": 1}))
    assert outcomes(count) == "succeeded 2, failed 1, stopped 1, still running 1"
    for word in ("succeeded", "failed", "stopped", "still running", "never run"):
        assert f"{word} (" in KEY or f"{word}: " in KEY, word
