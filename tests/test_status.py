"""The status line says what the executive waits for while the tree cannot tick."""

from __future__ import annotations

from frog_bt.rosbridge.link import LinkState
from frog_bt.runtime.status import link_line


def test_unreachable_rosbridge_is_named_with_attempt_delay_and_plain_reason():
    down = LinkState(
        connected=False,
        since=0.0,
        last_error="ConnectionRefusedError: [Errno 111] Connect call failed ('127.0.0.1', 9090)",
        attempt=4,
        retry_at=100.0 + 2.04,
    )
    line = link_line("ws://frog:9090", down, now=100.0)  # the countdown's clock, given
    assert line == (
        "rosbridge: connecting to ws://frog:9090 (attempt 4, next in 2.0 s): connection refused"
    )


def test_a_refused_auth_is_not_called_a_refused_connection():
    down = LinkState(
        connected=False,
        since=0.0,
        refused=True,
        attempt=2,
        last_error="connection closed (code 1000), right after connecting: authentication refused?",
    )
    assert link_line("ws://frog:9090", down).endswith(
        ": closed at once: authentication refused? (check the secret)"
    )


def test_before_the_first_attempt_fails_the_line_says_only_where():
    assert link_line("ws://frog:9090", LinkState(connected=False, since=0.0)) == (
        "rosbridge: connecting to ws://frog:9090"
    )


def test_connected_link_leaves_the_line_to_the_tree_unless_waiting_for_clock():
    up = LinkState(connected=True, since=0.0)
    assert link_line("ws://frog:9090", up) is None
    assert link_line("ws://frog:9090", up, clock_ready=False) == (
        "rosbridge: connected to ws://frog:9090, waiting for /clock"
    )


def test_a_ten_minute_outage_in_a_journal_is_a_few_dozen_lines() -> None:
    """Not a terminal: the status line prints states, not the countdown. A 10-minute
    outage (the client's own backoff, redrawn every 0.5 s as frog-bt run does) is driven
    on a clock the test moves; the lines are counted."""
    import io

    from frog_bt.rosbridge.client import backoff_delays
    from frog_bt.runtime.status import StatusLine

    out = io.StringIO()
    t, attempt, retry_at = 0.0, 0, 0.0
    delays = backoff_delays(0.25, 5.0)

    def source() -> str:
        link = LinkState(
            connected=False,
            since=0.0,
            attempt=attempt,
            retry_at=retry_at,
            last_error="ConnectionRefusedError: [Errno 111] Connect call failed",
        )
        return link_line("ws://frog:9090", link, now=t, countdown=False) or ""

    status = StatusLine(out, source=source)
    assert not status.tty
    while t < 600.0:
        if t >= retry_at:  # another attempt failed: the next one after the backoff
            attempt += 1
            retry_at = t + next(delays)
        status.update()
        t += 0.5
    lines = out.getvalue().splitlines()
    assert attempt > 100  # the client kept trying all along
    assert 5 <= len(lines) <= 36, lines
    assert lines[-1] == (
        "rosbridge: connecting to ws://frog:9090 (100+ attempts): connection refused"
    )
    assert not [line for line in lines if "next in" in line]


def test_attempt_counts_grow_in_steps() -> None:
    from frog_bt.runtime.status import milestone

    assert [milestone(n) for n in (0, 1, 2, 3, 4, 5, 9, 10, 19, 20, 49, 50, 99, 100, 201)] == [
        0,
        1,
        2,
        2,
        2,
        5,
        5,
        10,
        10,
        20,
        20,
        50,
        50,
        100,
        200,
    ]
