"""Replay of tours in which the robot asked for help and staff answered: the alert book,
the staff's decisions and the help state are rebuilt by the executive's own code, every
answer and every alert change is compared, and each recording replays "identical".

One recording per help condition (dock, undock, home, a persisting fault), each answered
with ``retry`` and with ``done_by_hand`` (refused, then done); ``ack_alert`` before and
after the alert was told again (escalation), from the console and from an
acknowledgement link; a kill -9 while help is pending and the restarted executive that
takes the help up again. A changed tree that no longer asks for help is reported at the
first difference, in domain terms. Each recording is made once for the module."""

from __future__ import annotations

import asyncio
import shutil
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

import pytest
from recorded_tour import scenario

from frog_bt import resources
from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.config import load_site
from frog_bt.engine.operator import Command
from frog_bt.live.recording import Recorder
from frog_bt.model import keys
from frog_bt.model.help import HelpAbout
from frog_bt.model.outcomes import DockingState
from frog_bt.offline.replay import Replay, ReplayResult
from frog_bt.recordings.commands import local_time
from frog_bt.recordings.mcapfile import open_recording
from frog_bt.rehearsal import Rehearsal
from frog_bt.runtime.executive import Executive
from frog_bt.runtime.observer import attach_all
from tests.e2e.tour import after_ticks

SITE = load_site()
Script = Callable[[Rehearsal], Awaitable[None]]


async def _record(path: Path, script: Script, rehearsal: Rehearsal, **recorder: Any) -> None:
    """Record ``rehearsal`` to ``path`` while ``script`` plays the people around it."""
    rec = Recorder(path, **recorder)
    rehearsal.prepare = lambda exe: attach_all(exe, [rec])
    try:
        async with rehearsal:
            await script(rehearsal)
    finally:
        rec.close()


def _rehearsal(data: dict[str, Any], **kwargs: Any) -> Rehearsal:
    return Rehearsal(scenario(data), site=SITE, once=False, memory=True, **kwargs)


async def _help(exe: Executive, about: HelpAbout, alert: str) -> None:
    """Until the robot asks about ``about`` and the alert ``alert`` is up."""
    await after_ticks(
        exe,
        lambda: (
            (h := exe.core.board.get(keys.HELP)) is not None
            and h.about is about
            and alert in exe.staff.book.active
        ),
        120,
    )


async def _answer(
    exe: Executive, command: Command, ok: bool, alert: str = "", by: str = ""
) -> None:
    answer = await exe.staff.submit(command, alert, by=by or "console")
    assert answer.ok is ok, answer.text


async def _retried(exe: Executive, about: HelpAbout, alert: str) -> None:
    """``retry``: the robot tries again (the help ends), fails again and asks again."""
    await _answer(exe, Command.RETRY, True)
    await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None)
    await _help(exe, about, alert)


async def _reports(exe: Executive, state: DockingState) -> None:
    await after_ticks(
        exe, lambda: (r := exe.core.board.get(keys.DOCKING)) is not None and r.value == state
    )


def _put_on_charger(r: Rehearsal) -> None:
    docking = r.sim.world.docking
    docking.state, docking.docked = "docked", True


async def _ended(r: Rehearsal) -> None:
    await r.sim.wait_for(lambda x: x.channel == "tour" and x.payload.get("state") == "ended", 60)


# ------------------------------------------------------------------ the people's scripts


async def _dock(r: Rehearsal) -> None:
    """The issue's tour: docking fails for good; staff acknowledge the alert, then answer
    ``done_by_hand`` through the console; here also a ``retry`` between, and a second
    acknowledgement (by link) once the alert has been told again."""
    exe = r.executive
    await _help(exe, HelpAbout.DOCK, "docking_failed")
    await _answer(exe, Command.ACK_ALERT, True, "docking_failed")  # before escalation
    await _answer(exe, Command.ACK_ALERT, False, "docking_failed")  # nothing left to ack
    await _retried(exe, HelpAbout.DOCK, "docking_failed")
    await after_ticks(exe, lambda: _told_again(exe, "docking_failed"), 60)
    await _answer(exe, Command.ACK_ALERT, True, "docking_failed", by="link")  # after it
    await _answer(exe, Command.DONE_BY_HAND, False)  # the robot does not report docked
    _put_on_charger(r)
    await _reports(exe, DockingState.DOCKED)
    await _answer(exe, Command.DONE_BY_HAND, True)
    await _ended(r)


def _told_again(exe: Executive, alert: str) -> bool:
    shown = exe.staff.book.unacknowledged.get(alert)
    return shown is not None and shown.repeat >= 1


async def _undock(r: Rehearsal) -> None:
    exe = r.executive
    await _help(exe, HelpAbout.UNDOCK, "undocking_failed")
    await _retried(exe, HelpAbout.UNDOCK, "undocking_failed")
    await _answer(exe, Command.DONE_BY_HAND, False)  # still on its charger
    docking = r.sim.world.docking  # a person pulls it off
    docking.state, docking.docked = "undocked", False
    await _reports(exe, DockingState.UNDOCKED)
    await _answer(exe, Command.DONE_BY_HAND, True)
    await r.sim.wait_for(lambda x: x.channel == "/GotoWayPoint", 30)  # on its way to POI0
    ticks = exe.core.ticks
    await after_ticks(exe, lambda: exe.core.ticks >= ticks + 20)


async def _home(r: Rehearsal) -> None:
    exe = r.executive
    await _help(exe, HelpAbout.HOME, "gave_up:home")
    await _retried(exe, HelpAbout.HOME, "gave_up:home")
    await _answer(exe, Command.DONE_BY_HAND, False)
    _put_on_charger(r)
    await _reports(exe, DockingState.DOCKED)
    await _answer(exe, Command.DONE_BY_HAND, True)
    await _ended(r)


async def _fault(r: Rehearsal) -> None:
    """A fault that persists with no tour: ``done_by_hand`` is refused while the robot
    reports it, the fault's alert is acknowledged, and ``retry`` is taken (the tree goes
    on as it does; the replay must follow it)."""
    exe = r.executive
    await _help(exe, HelpAbout.FAULT, "fault_persists")
    await _answer(exe, Command.DONE_BY_HAND, False)
    await _answer(exe, Command.ACK_ALERT, True, "fault")
    await _answer(exe, Command.RETRY, True)
    ticks = exe.core.ticks
    await after_ticks(exe, lambda: exe.core.ticks >= ticks + 50)


DOCK_FAILS = {"docking": {"dock_failures": 1000}}
UNDOCK_FAILS = {"docking": {"undock_failures": 1000}}
HOME_FAILS = {
    "navigation": {"failures": [{"poi": "SHOP", "times": 1000, "result": "aborted", "after": 3}]}
}
FAULT_PERSISTS = {
    "frontend": {"idle_at": 10_000},
    "faults": [{"at": 1, "name": "motors", "level": 2, "message": "overheated", "duration": 120}],
}
CASES: dict[str, tuple[dict[str, Any], Script]] = {
    "dock": (DOCK_FAILS, _dock),
    "undock": (UNDOCK_FAILS, _undock),
    "home": (HOME_FAILS, _home),
    "fault": (FAULT_PERSISTS, _fault),
}


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """One recording per help condition, made once."""
    out = tmp_path_factory.mktemp("help")
    paths = {}
    for name, (data, script) in CASES.items():
        paths[name] = out / f"{name}.mcap"
        asyncio.run(_record(paths[name], script, _rehearsal(data)))
    return paths


def replay(path: Path, tree: Any = None) -> ReplayResult:
    return Replay(path, SITE, tree or load_tree(site=SITE)).run()


@pytest.mark.parametrize("case", list(CASES))
def test_each_help_condition_answered_replays_identically(
    recorded: dict[str, Path], case: str
) -> None:
    result = replay(recorded[case])
    assert result.identical, (result.divergence, result.divergence and result.divergence.story)
    assert result.covered == result.end  # to its end
    assert result.operator_commands >= 3 and result.alerts >= 2  # answers and alerts compared


def test_the_issues_tour_replays_identically_with_every_answer_and_alert(
    recorded: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """ack_alert and done_by_hand through the console (and a retry, and an ack by link
    once the alert was told again): each answer and each alert change compared."""
    assert main(["replay", str(recorded["dock"]), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("identical: ") and ", 6 operator commands" in out
    states = [
        (m.alert.state, m.alert.repeat)
        for _, _, m in _messages(recorded["dock"], "/frog_bt/alert")
        if m.alert.id == "docking_failed"
    ]
    # raised, acknowledged; cleared by the retry; raised again, told again, acknowledged
    # (by link); cleared once docked by hand
    assert states == [
        ("raised", 0),
        ("acknowledged", 0),
        ("cleared", 0),
        ("raised", 0),
        ("raised", 1),
        ("acknowledged", 0),
        ("cleared", 0),
    ]
    answers = [
        (m.command, m.ok, m.by) for _, _, m in _messages(recorded["dock"], "/frog_bt/operator")
    ]
    assert answers == [
        ("ack_alert", True, "console"),
        ("ack_alert", False, "console"),
        ("retry", True, "console"),
        ("ack_alert", True, "link"),
        ("done_by_hand", False, "console"),
        ("done_by_hand", True, "console"),
    ]


def _messages(path: Path, channel: str) -> list[tuple[float, str, Any]]:
    """What ``channel`` holds, through the one reader: (t, channel, item)."""
    from frog_bt.recordings.reader import Reader

    return [
        (t, channel, item) for t, item in Reader(SITE, only={channel}).read(open_recording(path))
    ]


def test_a_tree_that_no_longer_asks_for_help_diverges_where_it_asked(
    recorded: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without AskForHelp on the way home, the dock's first difference is the alert
    docking_failed the recorded tree raised, told in domain terms."""
    trees = tmp_path / "trees"
    shutil.copytree(resources.tree_dir(), trees)
    home = trees / "home.yaml"
    home.write_text(  # the way home and the dock, retried, and no person asked
        home.read_text().replace("{type: AskForHelp, about: home}", "{type: GiveUp}")
    )
    path = recorded["dock"]
    raised = min(
        t for t, _, m in _messages(path, "/frog_bt/alert") if m.alert.kind == "docking_failed"
    )
    result = replay(path, load_tree(trees / "tour.yaml", SITE))
    div = result.divergence
    assert div is not None and div.expected is not None and div.got is not None
    assert div.t == raised  # at the first difference: where the recorded tree asked
    assert div.expected.payload == {"alert": "docking_failed", "state": "raised", "repeat": 0}
    assert div.got.payload == {"type": "tour", "state": "aborted", "reason": "dock failed"}
    when = local_time(raised)[11:19]
    story = (
        f"the alert docking_failed was raised at {when} in the recording; "
        "in the replay it was never raised"
    )
    assert div.story == story
    assert main(["replay", str(path), "--tree", str(trees / "tour.yaml"), "--quiet"]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[1].startswith("  expected: /frog_bt/alert {")
    assert out[4] == f"            {story}"
    assert out[5] == "  recorded: sent by the alert book (the executive)"
    assert out[6].startswith("  replayed: sent by GiveUp (home.yaml:22)")


# ------------------------------------------------------------------ kill -9 while help is pending


@pytest.fixture(scope="module")
def killed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """Docking fails for good; the alert is acknowledged; the executive is killed (its file
    cut where a kill -9 leaves it, nothing of its shutdown in it) while the robot waits; a
    new one takes the help up again from what staff decided, and the person answers it."""
    out = tmp_path_factory.mktemp("killed")
    first, cut, second = out / "first.mcap", out / "killed.mcap", out / "resumed.mcap"
    checkpoint = out / "checkpoint.json"
    kept: dict[str, Any] = {}

    async def until_killed(r: Rehearsal) -> None:
        exe = r.executive
        await _help(exe, HelpAbout.DOCK, "docking_failed")
        await _answer(exe, Command.ACK_ALERT, True, "docking_failed")
        keeper = r.keeper
        assert keeper is not None
        await after_ticks(exe, keeper.kept)  # saved
        ticks = exe.core.ticks
        await after_ticks(exe, lambda: exe.core.ticks >= ticks + 5)
        await asyncio.sleep(0)  # the recorder's last drain (and flush) runs
        cut.write_bytes(first.read_bytes())  # what a kill -9 now leaves
        kept["sim"], kept["listen"] = r.sim, r.listen
        r.own_sim = False  # the robot lives on

    async def resumed(r: Rehearsal) -> None:
        exe = r.executive
        await _help(exe, HelpAbout.DOCK, "docking_failed")
        assert "docking_failed" not in exe.staff.book.unacknowledged  # acknowledged before
        _put_on_charger(r)
        await _reports(exe, DockingState.DOCKED)
        await _answer(exe, Command.DONE_BY_HAND, True)
        await after_ticks(exe, lambda: exe.core.board.get(keys.HELP) is None)
        ticks = exe.core.ticks
        await after_ticks(exe, lambda: exe.core.ticks >= ticks + 20)

    async def main_() -> None:
        await _record(
            first, until_killed, _rehearsal(DOCK_FAILS, checkpoint=checkpoint), flush_every=0.0
        )
        sim = kept["sim"]
        again = Rehearsal(
            None, sim=sim, listen=kept["listen"], site=SITE, checkpoint=checkpoint, once=False
        )
        try:
            await _record(second, resumed, again)
        finally:
            await sim.stop()

    asyncio.run(main_())
    return cut, second


def test_a_kill_while_help_is_pending_and_the_resumed_executive_replay_identically(
    killed: tuple[Path, Path],
) -> None:
    cut, second = killed
    assert open_recording(cut).recovered  # cut short, as a kill leaves it
    first = replay(cut)
    assert first.identical, first.divergence
    (restored,) = [m for _, _, m in _messages(second, "/frog_bt/restored")]
    assert restored.help is not None and restored.help.about == "dock"
    assert restored.acknowledged == ["docking_failed"]
    result = replay(second)
    assert result.identical, (result.divergence, result.divergence and result.divergence.story)
    assert result.operator_commands == 1 and result.alerts >= 3


# ------------------------------------------------------------------ a day, one file per tour


def test_a_day_of_files_carries_the_alert_book_across_rotation(tmp_path: Path) -> None:
    """``--record DIR``: a stop given up raises its alert in the first tour's file; a
    person acknowledges it in the idle file after it, where the alert book is carried
    in the primer; the next tour clears it. Every file replays "identical" on its own."""
    from recorded_tour import FAST_TOURS

    from frog_bt.live.rotation import RecordingDir
    from frog_bt.model.events import Ticked
    from frog_bt.runtime.observer import listen
    from frog_bt.sim import scenario_from

    alert = "stop_given_up:POI2"
    day = RecordingDir(tmp_path, 10**9)
    data = {
        **FAST_TOURS,
        "frontend": {**FAST_TOURS["frontend"], "idle_after_tour": 30.0},
        "navigation": {
            **FAST_TOURS["navigation"],
            "failures": [{"poi": "POI2", "times": 1000, "result": "aborted", "after": 1}],
        },
    }

    async def run() -> None:
        two = asyncio.Event()

        def prepare(exe: Executive) -> None:
            attach_all(exe, [day])
            listen(exe, lambda _e: exe.outcome.tours >= 2 and two.set(), Ticked)

        rehearsal = Rehearsal(
            scenario_from("default", data), site=SITE, prepare=prepare, once=False, memory=True
        )
        async with rehearsal:
            exe = rehearsal.executive
            await after_ticks(
                exe, lambda: exe.outcome.tours >= 1 and alert in exe.staff.book.active
            )
            await _answer(exe, Command.ACK_ALERT, True, alert)
            await after_ticks(exe, lambda: alert not in exe.staff.book.active)  # next tour
            await asyncio.wait_for(two.wait(), 60)

    try:
        asyncio.run(run())
    finally:
        day.close()
    kinds = [p.name[16:20] for p in day.files]
    assert kinds[:4] == ["idle", "tour", "idle", "tour"], kinds
    acked = [p for p in day.files if _messages(p, "/frog_bt/operator")]
    assert [p.name[16:20] for p in acked] == ["idle"]  # the ack is in an idle file
    for path in day.files:
        result = replay(path)
        assert result.identical, (path.name, result.divergence, result.divergence.story)
