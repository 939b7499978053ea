"""The checkpoint file: atomic, versioned, cleared at the end of a tour, not resumed when old."""

from __future__ import annotations

import json
import time

from frog_bt.checkpoint import Progress, load, save


def test_progress_round_trips_and_an_empty_one_removes_the_file(tmp_path):
    path = tmp_path / "state" / "checkpoint.json"
    progress = Progress()
    progress.complete("start")
    progress.complete("recruit", visitor=7)
    save(path, progress)
    resume = load(path)
    assert resume is not None and resume.order == ["start", "recruit"] and resume.visitor == 7
    assert [p.name for p in path.parent.iterdir()] == ["checkpoint.json"]  # no temp file left
    progress.clear()
    save(path, progress)
    assert not path.exists()


def test_running_a_checkpoint_again_drops_it_and_everything_after():
    progress = Progress()
    for name in ("start", "recruit", "stop 0", "stop 1"):
        progress.complete(name)
    progress.begin("recruit")  # the visitor was lost: recruit again
    assert progress.done == ["start"]


def test_old_unreadable_or_foreign_checkpoints_are_not_resumed(tmp_path):
    path = tmp_path / "checkpoint.json"
    old = {"version": 1, "done": ["start"], "visitor": None, "written": time.time() - 1000}
    path.write_text(json.dumps(old))
    assert load(path, max_age=900) is None
    assert load(path, max_age=2000) is not None
    for text in ("not json", "[]", '{"version": 2, "done": ["start"]}',
                 '{"version": 1, "done": [], "written": 0}'):
        path.write_text(text)
        assert load(path) is None
    assert load(tmp_path / "missing.json") is None
