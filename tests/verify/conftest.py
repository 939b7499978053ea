"""What tests/verify shares: one recorded tour, and the shipped tree verified once per
run, through the command line as a designer runs it (``frog-bt verify --coverage
--conformance``), with the verdict it printed kept for the tests that read it.

The shipped tree is the most expensive thing verify does (every run of the real tree,
restarts included): it is explored once here, and every other test of verify explores a
small tree (:mod:`tests.verify.mutate`).
"""

from __future__ import annotations

import io
import sys
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from frog_bt.cli import main
from frog_bt.commands import verify as verify_command
from frog_bt.verify.prove import Verdict, prove
from tests import seasons

sys.path.insert(0, str(Path(__file__).parents[1] / "recording"))

from recorded_tour import record_tour

DATA = Path(__file__).parents[1] / "data"  # the suite's own recordings
SHIPPED_TIMEOUT = 900  # seconds: the first test to ask for it explores the shipped tree


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The test that explores the shipped tree (whichever asks first) may take minutes on
    a loaded machine: more than the suite's default timeout."""
    for item in items:
        if "shipped" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.timeout(SHIPPED_TIMEOUT))


@pytest.fixture(scope="session")
def one_tour(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The seeding, made once: one whole tour of the default scenario, nothing going
    wrong."""
    path = tmp_path_factory.mktemp("one-tour") / "tour.mcap"
    recorded = record_tour(path)
    assert recorded.outcome.code == 0, recorded.outcome.reason
    return path


@dataclass
class Shipped:
    """``frog-bt verify`` on the shipped tree and site: its exit, what it printed, the
    verdict it printed, and the recordings it checked."""

    code: int
    out: str
    err: str
    verdict: Verdict
    season: Path  # one recorded tour (``--coverage``)
    helped: Path  # the seeded season of tests/seasons.py (HELPED)


@pytest.fixture(scope="session")
def shipped(tmp_path_factory: pytest.TempPathFactory, one_tour: Path) -> Shipped:
    season = tmp_path_factory.mktemp("season")
    (season / "tour.mcap").write_bytes(one_tour.read_bytes())
    helped, _ = seasons.season(tmp_path_factory, "helped", **seasons.HELPED)
    verdicts: list[Verdict] = []

    def kept(*args: Any, **kwargs: Any) -> Verdict:
        found = prove(*args, **kwargs)
        verdicts.append(found)
        return found

    out, err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as patch, redirect_stdout(out), redirect_stderr(err):
        patch.setattr(verify_command, "prove", kept)
        code = main(
            [
                "verify",
                "--coverage",
                str(season),
                "--conformance",
                str(season),
                str(helped),
                str(DATA),
            ]
        )
    (verdict,) = verdicts  # explored once
    return Shipped(code, out.getvalue(), err.getvalue(), verdict, season, helped)
