import sys
from pathlib import Path

import pytest

# Shared test helpers (bench.py, ...) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))

# An executive that connects imports numpy in a thread (frog_bt/runtime/warm.py); a test
# that runs after it in the same process could see numpy half imported (pytest.approx
# looks it up in sys.modules). Imported here first, warm() finds it done.
import numpy  # noqa: F401

# The files that take longest (CPU seconds on this machine, measured per file), first:
# with -n 2 a worker takes whole files in collection order (pyproject.toml's
# --no-loadscope-reorder), and a long file taken last would leave the other worker idle
# while it runs. Only the order changes; every file still runs.
LONGEST_FIRST = (
    "tests/verify/test_verify.py",  # the shipped tree explored (about 80 s)
    "tests/report/test_report.py",  # its own season
    "tests/report/test_tours.py",  # a robot's day of every kind of tour
    "tests/recording/test_replay_help.py",
    "tests/e2e/test_demo.py",
    "tests/test_style.py",  # mypy, without a cache on a fresh clone
    "tests/report/test_seeded_help.py",  # the shared season
    "tests/report/test_runs.py",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    rank = {path: i for i, path in enumerate(LONGEST_FIRST)}
    root = Path(__file__).parent.parent
    items.sort(key=lambda item: rank.get(item.path.relative_to(root).as_posix(), len(rank)))
