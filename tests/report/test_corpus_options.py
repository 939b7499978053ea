"""scripts/corpus: its --help shows every default, and its defaults fit a small season."""

from __future__ import annotations

import itertools
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from corpus_run import HELP_EACH, HELP_KINDS, help_each_for, options, plan  # noqa: E402


def test_help_shows_every_default() -> None:
    out = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "corpus"), "--help"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    text = " ".join(out.split())
    for default in ("(default: 10)", "(default: 20)", "(default: 1)", "(default: 2)"):
        assert default in text, default
    assert f"(default: {HELP_EACH}, fewer when" in text  # --help-each, which depends on the season
    assert "--idle, --no-idle" in text and "(default: True)" in text


@pytest.mark.parametrize(
    ("days", "per_day", "each"), [(1, 3, 0), (1, 9, 0), (1, 10, 1), (2, 10, 2), (10, 20, 4)]
)
def test_the_defaults_fit_a_small_season(
    tmp_path: Path, days: int, per_day: int, each: int
) -> None:
    a = options(["--out", str(tmp_path), "--days", str(days), "--tours-per-day", str(per_day)])
    assert a.help_each == each == help_each_for(days * per_day)
    assert a.idle and a.seed == 1 and a.jobs == 2
    tours = plan(a.days, a.tours_per_day, a.seed, a.help_each)
    assert len(tours) == days * per_day
    helped = [t for t in tours if t.kind in HELP_KINDS]
    assert len(helped) == each * len(HELP_KINDS) <= len(tours) / 2


def test_help_each_given_too_large_is_said(tmp_path: Path, capsys) -> None:
    with pytest.raises(SystemExit) as exited:
        options(["--out", str(tmp_path), "--days", "1", "--tours-per-day", "3", "--help-each", "1"])
    assert exited.value.code == 2
    assert "do not fit a season of 3 tours" in capsys.readouterr().err


def test_each_tour_has_the_robots_time_in_service_around_it() -> None:
    """One robot's day cut in slots: each tour's opening and closing within its half-day,
    the slots one after another, the half-days covered from their start to their end."""
    tours = plan(1, 7, 1)
    edges = [(t.opens[11:16], t.start[11:16], t.closes[11:16]) for t in tours]
    assert edges[0][0] == "09:00" and edges[-1][2] == "18:00"
    for (_, _, closes), (opens, _, _) in itertools.pairwise(edges):
        assert closes == opens or (closes == "12:30" and opens == "14:30")
    assert all(o <= s < c for o, s, c in edges)
