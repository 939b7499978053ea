"""Who holds the staff token: the ``Bearer`` scheme only (RFC 6750), compared in constant
time, and short-lived tickets that let a page open its WebSocket without putting the token
in a URL (failed attempts: :mod:`~frog_bt.live.console.throttle`).

Clocks are passed in (monotonic seconds by default), so tests move time by hand.
"""

from __future__ import annotations

import hmac
import secrets
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

Clock = Callable[[], float]

TICKET_TTL = 30.0  # seconds a stream ticket may wait to be used (once)
MAX_TICKETS = 256  # tickets waiting at once; the oldest go first


def bearer(header: str | None) -> bytes | None:
    """The token of an ``Authorization: Bearer TOKEN`` header as bytes, else None (no
    header, another scheme, no token). Whatever bytes the header held, nothing raises:
    aiohttp hands undecodable bytes over as surrogates, which go back to bytes here."""
    if header is None:
        return None
    scheme, _, value = header.strip().partition(" ")
    if scheme.lower() != "bearer" or not value.strip():
        return None
    return value.strip().encode("utf-8", "surrogateescape")


def matches(given: bytes | None, token: str | None) -> bool:
    """Constant-time comparison (of equal-length digests, so the length leaks nothing)."""
    if given is None or token is None:
        return False
    return hmac.compare_digest(
        hmac.digest(b"frog-bt", given, "sha256"), hmac.digest(b"frog-bt", token.encode(), "sha256")
    )


@dataclass
class Tickets:
    """One-use tickets for the stream: ``POST /api/ticket`` (with the token) gives one,
    ``GET /api/stream?ticket=`` spends it within :data:`TICKET_TTL` seconds. A ticket is
    random and says nothing about the token."""

    clock: Clock = time.monotonic
    ttl: float = TICKET_TTL
    waiting: OrderedDict[str, float] = field(default_factory=OrderedDict)

    def issue(self) -> str:
        ticket = secrets.token_urlsafe(24)
        self.waiting[ticket] = self.clock() + self.ttl
        while len(self.waiting) > MAX_TICKETS:
            self.waiting.popitem(last=False)
        return ticket

    def spend(self, ticket: str) -> bool:
        """Whether ``ticket`` is valid now; it is gone either way."""
        expires = self.waiting.pop(ticket, None)
        return expires is not None and self.clock() <= expires
