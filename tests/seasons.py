"""Seeded seasons (scripts/corpus_run.py) recorded once per test run and shared by every
test file and every xdist worker that asks for the same one.

The first worker to ask records the season into the run's shared temporary folder while
holding a lock on it; any other waits on the lock and reads the manifest the first wrote
(``corpus.json``). A season is read, never changed: a test that wants to add or cut a
file copies it first.
"""

from __future__ import annotations

import fcntl
import json
import sys
from pathlib import Path
from typing import Any

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
from corpus_run import make

from tests.recording.recorded_tour import FAST_TOURS

# One day of seven fast tours, one of each help kind (HELP_KINDS), a bored visitor and a
# navigation failure: tests/report/test_seeded_help.py and test_report_page.py.
HELPED: dict[str, Any] = {"days": 1, "per_day": 7, "seed": 1, "help_each": 1}


def _root(factory: pytest.TempPathFactory) -> Path:
    """The folder every worker of this run shares (xdist gives each its own below it)."""
    base = factory.getbasetemp()
    return base.parent if base.name.startswith("popen-gw") else base


def season(
    factory: pytest.TempPathFactory, name: str, **settings: Any
) -> tuple[Path, dict[str, Any]]:
    """The season ``name`` (recorded with ``settings`` and fast tours) and its manifest."""
    root = _root(factory)
    directory = root / f"season-{name}"
    with (root / f"season-{name}.lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # bounded: the recorder's own tours end
        manifest = directory / "corpus.json"
        if not manifest.exists():
            make(directory, jobs=2, fast=FAST_TOURS, **settings)
        return directory, json.loads(manifest.read_text())
