"""Alert episodes across a robot's executive runs (frog_bt/offline/report/alerts.py):
an alert one run left up ends with that run, unless the condition outlived a quick
restart; escalations and acknowledgements stay in their episode."""

from __future__ import annotations

from frog_bt.offline.report.alerts import OUTLIVED, episodes, runs_of
from frog_bt.offline.report.facts import AlertChange, FileFacts, OperatorCall

HOUR = 3600.0


def run(start: float, end: float, *alerts: AlertChange) -> FileFacts:
    """One executive's run recorded in one file (no rotation metadata: a restart)."""
    return FileFacts(
        f"robot/{start:.0f}.mcap", restarts=[start], start=start, end=end, alerts=list(alerts)
    )


def raised(t: float, repeat: int = 0) -> AlertChange:
    return AlertChange(t, "battery_low", "battery_low", "raised", "WARN", repeat)


def acknowledged(t: float) -> AlertChange:
    return AlertChange(t, "battery_low", "battery_low", "acknowledged", "WARN")


def test_an_alert_left_up_by_a_run_ends_with_it() -> None:
    """Two runs hours apart, each raising and acknowledging the alert it then leaves up
    as it exits: two episodes, two acknowledgements, each with its own wait."""
    files = [
        run(0.0, 900.0, raised(100.0), acknowledged(190.0)),
        run(3 * HOUR, 3 * HOUR + 900.0, raised(3 * HOUR + 100.0), acknowledged(3 * HOUR + 130.0)),
    ]
    calls = [
        OperatorCall(190.0, "ack_alert", True, "", "battery_low", "console"),
        OperatorCall(3 * HOUR + 130.0, "ack_alert", True, "", "battery_low", "ctl"),
    ]
    got = episodes([a for f in files for a in f.alerts], calls, runs_of(files))
    assert [(e.raised, e.to_acknowledge, e.acknowledged_by, e.cleared) for e in got] == [
        (100.0, 90.0, "console", None),
        (3 * HOUR + 100.0, 30.0, "ctl", None),
    ]
    # without the runs, the second raise would be taken as the same alert still up
    assert len(episodes([a for f in files for a in f.alerts], calls)) == 1


def test_a_condition_that_outlives_a_quick_restart_is_one_episode() -> None:
    """systemd brings a new executive up seconds after the old one died; the battery is
    still low, so the new one raises the alert again at once (and restores the
    acknowledgement): the same episode, acknowledged when the person first did."""
    files = [
        run(0.0, 500.0, raised(100.0), acknowledged(190.0)),
        run(505.0, 2000.0, raised(506.0), acknowledged(506.0)),
    ]
    got = episodes([a for f in files for a in f.alerts], [], runs_of(files))
    assert [(e.raised, e.acknowledged) for e in got] == [(100.0, 190.0)]
    # raised again only after OUTLIVED seconds from the old run's end: a new episode
    late = 500.0 + OUTLIVED + 1.0
    files[1] = run(505.0, 2000.0, raised(late))
    got = episodes([a for f in files for a in f.alerts], [], runs_of(files))
    assert [e.raised for e in got] == [100.0, late]


def test_escalations_stay_in_their_episode() -> None:
    files = [run(0.0, 2000.0, raised(100.0), raised(400.0, 1), raised(700.0, 2))]
    (episode,) = episodes(files[0].alerts, [], runs_of(files))
    assert (episode.raised, episode.repeats, episode.acknowledged) == (100.0, 2, None)
