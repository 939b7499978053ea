"""The status line says what the executive waits for while the tree cannot tick."""

from __future__ import annotations

from frog_bt.observers.status import link_line
from frog_bt.rosbridge.link import LinkState


def test_unreachable_rosbridge_is_named_with_attempt_delay_and_plain_reason():
    down = LinkState(connected=False, since=0.0, last_error="ConnectionRefusedError: [Errno 111] "
                     "Connect call failed ('127.0.0.1', 9090)", attempt=4,
                     retry_at=100.0 + 2.04)
    line = link_line("ws://frog:9090", down, now=100.0)  # the countdown's clock, given
    assert line == ("rosbridge: connecting to ws://frog:9090 (attempt 4, next in 2.0 s): "
                    "connection refused")


def test_a_refused_auth_is_not_called_a_refused_connection():
    down = LinkState(connected=False, since=0.0, refused=True, attempt=2,
                     last_error="connection closed (code 1000), right after connecting: "
                                "authentication refused?")
    assert link_line("ws://frog:9090", down).endswith(
        ": closed at once: authentication refused? (check the secret)")


def test_before_the_first_attempt_fails_the_line_says_only_where():
    assert link_line("ws://frog:9090", LinkState(connected=False, since=0.0)) == (
        "rosbridge: connecting to ws://frog:9090")


def test_connected_link_leaves_the_line_to_the_tree_unless_waiting_for_clock():
    up = LinkState(connected=True, since=0.0)
    assert link_line("ws://frog:9090", up) is None
    assert link_line("ws://frog:9090", up, clock_ready=False) == (
        "rosbridge: connected to ws://frog:9090, waiting for /clock")
