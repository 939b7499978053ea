import compileall
import os
import sys
from pathlib import Path

import pytest

# Shared test helpers (bench.py, ...) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))

# Where PYTHONDONTWRITEBYTECODE is set (this machine sets it), every `frog-bt` a test
# starts would compile the package anew, as an installed package never does (pip
# compiles it): compiled once here, by the process that starts the workers (0.3 s; it
# saved 6 % of the CPU time of the files that start most of them).
if sys.dont_write_bytecode and "PYTEST_XDIST_WORKER" not in os.environ:
    compileall.compile_dir(Path(__file__).parents[1] / "frog_bt", quiet=1)

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
