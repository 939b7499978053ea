"""Who holds the staff token: the ``Bearer`` scheme only (RFC 6750), failed attempts
throttled per address and logged at most once a minute, and short-lived tickets that let
a page open its WebSocket without putting the token in a URL.

Clocks are passed in (monotonic seconds by default), so tests move time by hand.
"""

from __future__ import annotations

import hmac
import logging
import secrets
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

log = logging.getLogger(__name__)
Clock = Callable[[], float]

TICKET_TTL = 30.0  # seconds a stream ticket may wait to be used (once)
MAX_TICKETS = 256  # tickets waiting at once; the oldest go first
FAIL_BURST = 10  # failed attempts an address may make at once ...
FAIL_EVERY = 6.0  # ... then one more every this many seconds
LOG_EVERY = 60.0  # seconds between log lines about failed attempts
MAX_ADDRESSES = 4096  # addresses remembered; the least recently seen go first


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
class _Bucket:
    tokens: float
    at: float


@dataclass
class Failures:
    """Failed token attempts, per address: :data:`FAIL_BURST` at once, then one every
    :data:`FAIL_EVERY` seconds; beyond that an address is refused (429) before its token
    is even looked at, right or wrong. Logged at most every :data:`LOG_EVERY` seconds, as
    one line with the count and the addresses (:meth:`flush` says what is left)."""

    clock: Clock = time.monotonic
    buckets: OrderedDict[str, _Bucket] = field(default_factory=OrderedDict)
    unlogged: int = 0
    unlogged_from: set[str] = field(default_factory=set)
    logged_at: float | None = None

    def _bucket(self, address: str) -> _Bucket:
        now = self.clock()
        bucket = self.buckets.pop(address, None) or _Bucket(float(FAIL_BURST), now)
        bucket.tokens = min(FAIL_BURST, bucket.tokens + (now - bucket.at) / FAIL_EVERY)
        bucket.at = now
        self.buckets[address] = bucket  # most recently seen last
        while len(self.buckets) > MAX_ADDRESSES:
            self.buckets.popitem(last=False)
        return bucket

    def allowed(self, address: str) -> bool:
        """Whether ``address`` may try a token now."""
        return self._bucket(address).tokens >= 1.0

    def failed(self, address: str) -> None:
        """``address`` gave a wrong or no token."""
        bucket = self._bucket(address)
        bucket.tokens = max(0.0, bucket.tokens - 1.0)
        self.unlogged += 1
        if len(self.unlogged_from) < 5:
            self.unlogged_from.add(address)
        self.flush()

    def flush(self) -> None:
        """Log what was counted, unless a line went out less than a minute ago."""
        now = self.clock()
        if not self.unlogged or (self.logged_at is not None and now - self.logged_at < LOG_EVERY):
            return
        log.warning(
            "console: %d failed token attempt%s (from %s)",
            self.unlogged,
            "" if self.unlogged == 1 else "s",
            ", ".join(sorted(self.unlogged_from)),
        )
        self.unlogged, self.unlogged_from, self.logged_at = 0, set(), now


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
