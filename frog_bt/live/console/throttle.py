"""Who is asking, and how fast: the client a request stands for, the command rate per
client, and failed attempts that slow down only failures. Sans-I/O; clocks are passed in
(monotonic seconds by default), so tests move time by hand.

* :func:`client_of`: the connection's address, or, when that address is one of
  ``console.trusted_proxies``, the nearest address in ``X-Forwarded-For`` that is not a
  trusted proxy (the header is read from the right: only the trusted proxies' own
  additions are believed). A request from anywhere else may say what it likes in
  ``X-Forwarded-For``: it is not read.
* :class:`Rates`: at most ``rate`` commands a second per client (a token bucket of one
  second's worth, but never less than :data:`COMMAND_BURST`): CONTRACT §7's ``429 when
  commands come too fast``. Failed attempts never touch it.
* :class:`Failures`: a wrong or missing token (or a bad acknowledgement link) is a
  failure. Each is counted, per client and in total, and logged in the next summary line
  (at most one a minute). A client's failures beyond :data:`FAIL_BURST` (then one every
  :data:`FAIL_EVERY` seconds), or everyone's beyond :data:`TOTAL_BURST` (then one every
  :data:`TOTAL_EVERY` seconds), are answered 429 instead of 401. A request with the right
  token is never looked at here: nobody's failures, not even its own client's, refuse it.
  That is safe because a token is 16 to 512 visible characters: at the rate any console
  answers, guessing one is hopeless, and the throttle is about the noise and the cost.
"""

from __future__ import annotations

import ipaddress
import logging
import time
from collections import Counter, OrderedDict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

log = logging.getLogger(__name__)
Clock = Callable[[], float]
Network = ipaddress.IPv4Network | ipaddress.IPv6Network

FAIL_BURST = 10  # failed attempts a client may make at once ...
FAIL_EVERY = 6.0  # ... then one more every this many seconds
TOTAL_BURST = 100  # failed attempts of all clients together at once ...
TOTAL_EVERY = 0.5  # ... then one more every this many seconds
COMMAND_BURST = 10  # commands a client may send at once, whatever the rate
LOG_EVERY = 60.0  # seconds between summary lines about failed attempts
MAX_CLIENTS = 4096  # clients remembered; the least recently seen go first
SHOWN_CLIENTS = 5  # clients named in a summary line (the busiest)


def networks(texts: Iterable[str]) -> tuple[Network, ...]:
    """``console.trusted_proxies`` as networks (an address alone is a /32 or /128)."""
    return tuple(ipaddress.ip_network(t, strict=False) for t in texts)


def _address(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    text = text.strip()
    if text.startswith("[") and "]" in text:  # [::1]:port
        text = text[1 : text.index("]")]
    elif text.count(":") == 1:  # 10.0.0.1:port
        text = text.split(":", 1)[0]
    try:
        return ipaddress.ip_address(text)
    except ValueError:
        return None


def _trusted(address: str, proxies: Sequence[Network]) -> bool:
    ip = _address(address)
    return ip is not None and any(ip in net for net in proxies)


def client_of(remote: str | None, forwarded_for: Sequence[str], proxies: Sequence[Network]) -> str:
    """The client a request stands for: ``remote`` (the connection's address), unless it is
    a trusted proxy; then the rightmost ``X-Forwarded-For`` hop that is not one (every
    ``X-Forwarded-For`` header, in order, comma-separated). A hop that is not an address
    ends the walk at the last proxy believed (its text is never shown)."""
    client = remote or "?"
    if not proxies or not _trusted(client, proxies):
        return client
    hops = [h for header in forwarded_for for h in header.split(",") if h.strip()]
    for hop in reversed(hops):
        ip = _address(hop)
        if ip is None:
            return client
        client = str(ip)
        if not any(ip in net for net in proxies):
            return client
    return client


@dataclass
class _Bucket:
    tokens: float
    at: float

    def refill(self, now: float, burst: float, every: float) -> None:
        self.tokens = min(burst, self.tokens + (now - self.at) / every)
        self.at = now

    def take(self) -> bool:
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False


@dataclass
class Rates:
    """At most ``rate`` commands a second per client (at most :data:`COMMAND_BURST` or one
    second's worth at once, whichever is more)."""

    rate: float
    clock: Clock = time.monotonic
    buckets: OrderedDict[str, _Bucket] = field(default_factory=OrderedDict)

    def take(self, client: str) -> bool:
        """Whether ``client`` may send a command now (and it is counted)."""
        burst = max(float(COMMAND_BURST), self.rate)
        bucket = _recent(self.buckets, client, lambda: _Bucket(burst, self.clock()))
        bucket.refill(self.clock(), burst, 1.0 / self.rate)
        return bucket.take()


def _recent(buckets: OrderedDict[str, _Bucket], key: str, new: Callable[[], _Bucket]) -> _Bucket:
    """``key``'s bucket, as the most recently seen; the least recently seen go beyond
    :data:`MAX_CLIENTS`."""
    bucket = buckets.pop(key, None) or new()
    buckets[key] = bucket
    while len(buckets) > MAX_CLIENTS:
        buckets.popitem(last=False)
    return bucket


@dataclass
class Failures:
    """Failed attempts: every one counted (per client and in total) and logged in a summary
    line at most every :data:`LOG_EVERY` seconds; :meth:`failed` says whether this one is
    over its client's or everyone's budget (then it is answered 429)."""

    clock: Clock = time.monotonic
    buckets: OrderedDict[str, _Bucket] = field(default_factory=OrderedDict)
    total: _Bucket | None = None
    counted: int = 0  # every failure since start
    unlogged: int = 0
    unlogged_throttled: int = 0
    unlogged_from: Counter[str] = field(default_factory=Counter)
    logged_at: float | None = None

    def failed(self, client: str) -> bool:
        """``client`` gave a wrong or no token: counted; True when it is over a budget."""
        now = self.clock()
        self.counted += 1
        self.unlogged += 1
        if client in self.unlogged_from or len(self.unlogged_from) < MAX_CLIENTS:
            self.unlogged_from[client] += 1
        mine = _recent(self.buckets, client, lambda: _Bucket(float(FAIL_BURST), now))
        mine.refill(now, FAIL_BURST, FAIL_EVERY)
        if self.total is None:
            self.total = _Bucket(float(TOTAL_BURST), now)
        self.total.refill(now, TOTAL_BURST, TOTAL_EVERY)
        throttled = not mine.take() or not self.total.take()
        self.unlogged_throttled += throttled
        self.flush()
        return throttled

    def flush(self) -> None:
        """Log what was counted, unless a line went out less than a minute ago."""
        now = self.clock()
        if not self.unlogged or (self.logged_at is not None and now - self.logged_at < LOG_EVERY):
            return
        busiest = self.unlogged_from.most_common(SHOWN_CLIENTS)
        others = len(self.unlogged_from) - len(busiest)
        where = ", ".join(f"{client} {n}" for client, n in busiest)
        log.warning(
            "console: %d failed token attempt%s, %d of them answered 429 (from %s%s)",
            self.unlogged,
            "" if self.unlogged == 1 else "s",
            self.unlogged_throttled,
            where,
            f" and {others} more" if others else "",
        )
        self.unlogged, self.unlogged_throttled, self.logged_at = 0, 0, now
        self.unlogged_from = Counter()
