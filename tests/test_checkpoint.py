"""The checkpoint file: atomic, versioned, cleared at the end of a tour, not resumed when old."""

from __future__ import annotations

import json
import time
import uuid

import pytest

from frog_bt.errors import UsageError
from frog_bt.model.tours import StopVisit, TourRow
from frog_bt.runtime.checkpoint import Progress, Resume, claim, default_path, load, save


def test_progress_round_trips_and_an_empty_one_removes_the_file(tmp_path):
    path = tmp_path / "state" / "checkpoint.json"
    progress = Progress().complete("start").complete("recruit", visitor=7)
    save(path, progress)
    resume = load(path)
    assert resume is not None and resume.order == ("start", "recruit") and resume.visitor == 7
    assert resume.done == {"start", "recruit"}
    assert [p.name for p in path.parent.iterdir()] == ["checkpoint.json"]  # no temp file left
    save(path, Progress())
    assert not path.exists()


def test_the_checkpoint_keeps_the_run_id_of_the_executive_that_wrote_it(tmp_path):
    """A resumed executive's recordings keep the run id: the checkpoint carries it; one
    written before run ids (or with something else there) resumes with none."""
    path = tmp_path / "checkpoint.json"
    run = str(uuid.uuid4())
    save(path, Progress().complete("start"), run)
    resume = load(path)
    assert resume is not None and resume.run == run
    for foreign in ({}, {"run": "not a uuid\x1b[2J"}, {"run": 7}):
        data = {"version": 1, "done": ["start"], "visitor": None, "written": time.time()}
        path.write_text(json.dumps({**data, **foreign}))
        resume = load(path)
        assert resume is not None and resume.run == ""


def test_the_checkpoint_keeps_the_tours_row_as_counted(tmp_path):
    """The tour so far (the one count of tours' row) goes with the progress, so that a
    resumed executive counts the stops before the restart; one not kept, or not a row,
    resumes without it."""
    path = tmp_path / "checkpoint.json"
    row = TourRow(started=5.0, stops=[StopVisit("POI1", arrived=True, a_end=9.0)], accepted=1)
    save(path, Progress().complete("start").complete("stop 0"), tour=row)
    resume = load(path)
    assert resume is not None and resume.tour == row and resume.order == ("start", "stop 0")
    data = json.loads(path.read_text())
    for tour in ({"stops": "POI1"}, None):
        path.write_text(json.dumps({**data, "tour": tour}))
        resume = load(path)
        assert resume is not None and resume.tour is None and resume.order


def test_running_a_checkpoint_again_drops_it_and_everything_after():
    progress = Progress()
    for name in ("start", "recruit", "stop 0", "stop 1"):
        progress = progress.complete(name)
    again = progress.begin("recruit")  # the visitor was lost: recruit again
    assert again.done == ("start",)
    assert progress.done == ("start", "recruit", "stop 0", "stop 1")  # values: not mutated
    assert again.begin("stop 5") is again


def test_old_unreadable_or_foreign_checkpoints_are_not_resumed(tmp_path):
    path = tmp_path / "checkpoint.json"
    old = {"version": 1, "done": ["start"], "visitor": None, "written": time.time() - 1000}
    path.write_text(json.dumps(old))
    assert load(path, max_age=900) is None
    assert load(path, max_age=2000) is not None
    for text in (
        "not json",
        "[]",
        '{"version": 2, "done": ["start"]}',
        '{"version": 1, "done": [], "written": 0}',
    ):
        path.write_text(text)
        assert load(path) is None
    assert load(tmp_path / "missing.json") is None


def test_default_checkpoints_are_per_site_config_and_listen_address(tmp_path):
    site_a, site_b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    paths = {
        default_path(site, listen, tmp_path)
        for site in (site_a, site_b)
        for listen in (("127.0.0.1", 5006), ("127.0.0.1", 5016))
    }
    assert len(paths) == 4
    assert default_path(site_a, ("127.0.0.1", 5006), tmp_path) == default_path(
        tmp_path / "." / "a.yaml", ("127.0.0.1", 5006), tmp_path
    )


def test_a_claimed_checkpoint_cannot_be_claimed_again_until_released(tmp_path):
    path = tmp_path / "state" / "cp.json"
    first = claim(path)
    with pytest.raises(UsageError, match="in use by another running executive"):
        claim(path)
    first.close()
    claim(path).close()


def test_resume_is_announced_where_the_tour_picks_up_and_how_old_it_is():
    stops = ["POI1", "POI2", "POI3"]
    done = ("start", "recruit", "stop 0")
    resume = Resume(frozenset(done), 7, done, 1000.0)
    assert resume.announce(stops, now=1180.0) == ("resuming the tour at POI2: checkpoint 3 min old")
    assert Resume(frozenset(), None, ("start", "recruit"), 1000.0).announce(stops, 1010.0) == (
        "resuming the tour at POI1: checkpoint 10 s old"
    )
    assert Resume(frozenset(), None, ("start",), 0.0).where(stops) == "at the recruitment"
    assert Resume(frozenset(), None, ("start", "recruit", "stop 2"), 0.0).where(stops) == (
        "on the way back to the dock"
    )
