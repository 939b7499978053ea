"""The executive only runs: it is handed its links, its tick ticks, and what ends a run
(the exit rules) and what outlives it (the keeper's files) are observers attached beside it.

Every test here hands the executive fake links (tests/links.py): no socket, no simulator.
"""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from links import FakeFrontend, FakeRobot

from frog_bt.behaviours import load_tree
from frog_bt.clock import WallClock
from frog_bt.config import load_site
from frog_bt.model import keys
from frog_bt.model.events import Ticked
from frog_bt.model.help import Help, HelpAbout
from frog_bt.model.outcomes import Incident, IncidentKind, TourState
from frog_bt.model.progress import Progress
from frog_bt.model.wire import INPUTS, OUTPUTS
from frog_bt.rosbridge.link import LinkState
from frog_bt.runtime import checkpoint, decisions
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.exits import ExitRules
from frog_bt.runtime.keeper import Keeper
from frog_bt.runtime.observer import attach_all, listen

SITE = load_site()
TREE = load_tree(site=SITE)


def executive() -> tuple[Executive, FakeRobot, FakeFrontend]:
    robot, frontend = FakeRobot(), FakeFrontend()
    return Executive(SITE, TREE, WallClock(), robot, frontend), robot, frontend


def test_the_executive_takes_the_links_it_is_handed() -> None:
    exe, robot, frontend = executive()
    assert exe.client is robot and exe.link is frontend
    assert robot.on_input is not None and frontend.on_message is not None  # it listens
    exe.setup_wire()
    assert robot.advertised == {t.name: t.type for t in OUTPUTS.values()}
    assert robot.subscribed == {t.name: t.type for t in INPUTS.values()}


def test_tick_ticks_and_decides_nothing_about_the_run() -> None:
    """A tree that fails: tick() says so; without exit rules, the executive goes on."""
    exe, _, _ = executive()
    heard: list[Ticked] = []
    listen(exe, heard.append, Ticked)
    status = exe.tick()
    assert status.name == "RUNNING" and [e.tick for e in heard] == [1]
    exe.core.board.set(keys.HELP, Help(HelpAbout.DOCK, 0.0))
    exe.tick()
    assert exe.outcome.reason == "" and not exe._stopping.is_set()


def test_in_the_loop_the_observers_hear_the_ticks_end_before_tick_returns() -> None:
    """The executive settles its observers itself once the tick's commands are out: no
    loop handle per tick, and nothing heard late."""

    async def main() -> None:
        exe, _, _ = executive()
        heard: list[Ticked] = []
        listen(exe, heard.append, Ticked)
        loop = asyncio.get_running_loop()
        ready = len(loop._ready)  # type: ignore[attr-defined]
        exe.tick()
        assert [e.tick for e in heard] == [1]
        assert len(loop._ready) == ready  # type: ignore[attr-defined]

    asyncio.run(main())


@pytest.mark.parametrize(
    ("once", "board", "status", "stopped", "tours"),
    [
        (True, {keys.TOUR_STATE: TourState.ENDED}, "SUCCESS", (0, "tour ended docked"), 1),
        (False, {keys.TOUR_STATE: TourState.ENDED}, "SUCCESS", None, 1),
        (True, {keys.TOUR_STATE: TourState.ABORTED}, "SUCCESS", (1, "tour aborted: "), 0),
        (False, {keys.TOUR_STATE: TourState.ABORTED}, "SUCCESS", None, 0),
        (True, {keys.HELP: Help(HelpAbout.DOCK, 0.0)}, "RUNNING", (1, "needs help: "), 0),
        (False, {keys.HELP: Help(HelpAbout.DOCK, 0.0)}, "RUNNING", None, 0),
        (False, {}, "FAILURE", (1, "the tour tree failed"), 0),
        (
            False,
            {keys.GAVE_UP: Incident(0.0, IncidentKind.GAVE_UP, "no robot")},
            "FAILURE",
            (1, "no robot"),
            0,
        ),
        (True, {}, "RUNNING", None, 0),
    ],
)
def test_the_exit_rules(
    once: bool, board: dict, status: str, stopped: tuple[int, str] | None, tours: int
) -> None:
    exe, _, _ = executive()
    rules = ExitRules(once)
    attach_all(exe, [rules])
    for key, value in board.items():
        exe.core.board.set(key, value)
    rules.on_event(Ticked(0.0, 1, status))  # type: ignore[arg-type]
    assert rules.tours == tours
    if stopped is None:
        assert not exe._stopping.is_set()
    else:
        assert exe._stopping.is_set() and exe.outcome.code == stopped[0]
        assert exe.outcome.reason.startswith(stopped[1])


def test_three_refused_connections_end_a_once_run() -> None:
    for once in (False, True):
        exe, robot, _ = executive()
        attach_all(exe, [ExitRules(once)])
        for _ in range(3):  # each goes up, then is closed at once
            robot.connect()
            robot._link = LinkState(connected=False, since=0.0, refused=True)
            robot.on_link(robot.link)  # as the client tells the executive
        assert exe._stopping.is_set() is once
        if once:
            assert exe.outcome == type(exe.outcome)(1, exe.outcome.reason)
            assert "refused authentication" in exe.outcome.reason


def test_the_keeper_resumes_a_checkpoint_and_keeps_what_changes(tmp_path: Path) -> None:
    path = tmp_path / "checkpoint.json"
    checkpoint.save(path, Progress().complete("start").complete("recruit", visitor=7))
    decisions.save(decisions.path_for(path), decisions.Decisions(in_service=False))
    exe, _, _ = executive()
    keeper = Keeper(path)
    attach_all(exe, [keeper])
    resume = exe.core.board.get(keys.RESUME)
    assert resume is not None and resume.order == ("start", "recruit") and resume.visitor == 7
    assert exe.core.board.get(keys.IN_SERVICE) is False
    assert exe.restored is not None and exe.restored.done == ["start", "recruit"]
    exe.core.board.set(keys.IN_SERVICE, True)  # service_on
    exe.core.board.set(keys.PROGRESS, Progress().complete("start"))
    assert not keeper.kept()
    exe.tick()  # the keeper writes after the tick
    assert keeper.kept()
    assert decisions.load(decisions.path_for(path)) == decisions.NONE  # nothing decided
    again = checkpoint.load(path)
    assert again is not None and again.order == ("start",) and again.resumed == 0


def test_a_fresh_start_takes_nothing_up(tmp_path: Path) -> None:
    path = tmp_path / "checkpoint.json"
    checkpoint.save(path, Progress().complete("start"))
    exe, _, _ = executive()
    attach_all(exe, [Keeper(path, fresh=True)])
    assert exe.core.board.get(keys.RESUME) is None and exe.restored is None


def test_a_crashed_tour_is_not_resumed_into_the_same_crash(tmp_path: Path) -> None:
    path = tmp_path / "checkpoint.json"
    checkpoint.save(path, Progress().complete("start"))
    Keeper(path).crashed(RuntimeError("boom"))
    exe, _, _ = executive()
    attach_all(exe, [Keeper(path)])
    assert exe.core.board.get(keys.RESUME) is None
    held = exe.core.board.get(keys.HELP_RESTORED)
    assert held is not None and held.about is HelpAbout.CRASHED and "boom" in held.detail
    assert not path.exists() and path.with_name(path.name + ".crashed").exists()


def test_a_keeper_keeps_only_an_executive() -> None:
    class Replay:
        pass

    with pytest.raises(TypeError, match="executive"):
        Keeper(Path("x")).attach(Replay())  # type: ignore[arg-type]


def test_run_connects_ticks_and_leaves_the_links_tidy() -> None:
    """The whole run on fake links: started, ticked, stopped; the robot's topics left and
    both links closed."""

    async def main() -> tuple[Executive, FakeRobot]:
        exe, robot, _ = executive()
        ticked = asyncio.Event()
        listen(exe, lambda _e: ticked.set(), Ticked)
        task = asyncio.create_task(exe.run())
        await asyncio.wait_for(ticked.wait(), 10)
        exe.stop("test over", 3)
        outcome = await asyncio.wait_for(task, 10)
        assert (outcome.code, outcome.reason) == (3, "test over")
        return exe, robot

    exe, robot = asyncio.run(main())
    assert robot.link.connected and exe.was_connected
    assert robot.left and robot.closed
