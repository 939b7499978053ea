"""Small tours made of the shipped trees' parts, with one edit, for verify's tests.

The shipped tour is explored once per run (tests/verify/conftest.py): every run of it is
the most expensive thing verify does. A mutation is shown on :data:`SMALL`, a tour of
the shipped parts (the abort guard, the start, the way home and docking, the drive with
its retries, ``recruit.yaml`` where a test wants it) with one stop and no checkpoint
(nothing to restart from: the resumed runs are tests/verify/test_real.py's), written
beside a copy of the shipped trees: every real node, only fewer of them.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest

from frog_bt import resources
from frog_bt.behaviours import FACTORY
from frog_bt.config import Site, load_site
from frog_bt.tree.factory import NodeFactory
from frog_bt.verify.graph import Run
from frog_bt.verify.prove import Verdict, prove
from frog_bt.verify.report import tick_line

SMALL = """\
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
        - {include: home.yaml}
        - {type: ClearAbort}
    - type: Sequence
      name: FROG tour
      memory: true
      children:
        - {type: ConfirmResume}
        - type: Sequence
          name: Start a tour
          memory: true
          scope: tour
          children:
            - type: Sequence
              name: Ready to start
              memory: false
              children:
                - {type: WaitInService, name: Wait while out of service}
                - {type: WaitFrontendIdle, name: Wait for the front end}
            - {type: TourStatus, state: started}
            - {type: Docking, action: undock}
        - type: Sequence
          name: Visit POI1
          memory: true
          children:
            - {include: goto.yaml, with: {poi: POI1}}
            - {type: PlayContent, poi: POI1, part: a}
        - {include: home.yaml}
        - {type: TourStatus, state: ended}
"""
RECRUIT = """        - type: Sequence
          name: Visit POI1
"""
WITH_RECRUIT = """        - {include: recruit.yaml}
        - type: Sequence
          name: Visit POI1
"""


def copy(
    tmp_path: Path,
    edits: dict[str, list[tuple[str, str]]],
    recruit: bool = False,
    small: bool = True,
) -> Path:
    """The shipped trees in ``tmp_path/trees``, :data:`SMALL` as tour.yaml (``recruit``:
    with ``recruit.yaml`` before the stop; not ``small``: the shipped tour), with
    ``edits`` (file -> [(old, new)]) made; the path of tour.yaml. Each ``old`` must be
    there once."""
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    if small:
        (trees / "tour.yaml").write_text(SMALL.replace(RECRUIT, WITH_RECRUIT) if recruit else SMALL)
    for name, changes in edits.items():
        text = (trees / name).read_text()
        for old, new in changes:
            assert text.count(old) == 1, f"{name}: {old!r} is not there once"
            text = text.replace(old, new)
        (trees / name).write_text(text)
    return trees / "tour.yaml"


def site() -> Site:
    return load_site(None)


def verdict(tour: Path, factory: NodeFactory = FACTORY, restarts: bool = False) -> Verdict:
    """``tour`` proved (``restarts``: from its checkpoints too; a mutation breaks a
    property on a fresh start)."""
    s = site()
    return prove(factory.load(tour, s), s, restarts=restarts)


def run_of(v: Verdict, name: str) -> Run:
    """The run that breaks property ``name`` (it must be broken)."""
    found = [b for b in v.broken if b.name == name]
    assert found, f"{name} holds; broken: {[b.name for b in v.broken]}"
    return found[0].run


def lines(v: Verdict, run: Run) -> list[str]:
    return [tick_line(v.model, step) for _, step, _ in run.ticks]


def cli(patch: pytest.MonkeyPatch, *args: str) -> tuple[int, Verdict | None]:
    """``frog-bt ARGS``, with the verdict it printed (None: it explored nothing): a test
    reads both, from one exploration."""
    from frog_bt.cli import main
    from frog_bt.commands import verify
    from frog_bt.verify import prove as proving

    found: list[Verdict] = []

    def kept(*a: Any, **k: Any) -> Verdict:
        v = prove(*a, **k)
        found.append(v)
        return v

    patch.setattr(verify, "prove", kept)
    patch.setattr(proving, "prove", kept)  # check imports it as it runs
    code = main(list(args))
    assert len(found) <= 1
    return code, found[0] if found else None
