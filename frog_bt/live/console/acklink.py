"""Signed links that acknowledge one alert from a phone: sans-I/O, no clock of its own.

A notification carries ``{console_url}/ack/{alert_id}?exp=EXP&sig=SIG``. ``EXP`` is the
wall-clock epoch second the link expires (the phone's request comes in real time, so the
project clock, simulated in a rehearsal, is not the one to hold it against); ``SIG`` is
HMAC-SHA256 over the alert's id and ``EXP``, hex, under a key *derived* from the console's
token (:func:`link_key`): the token itself never leaves the executive, and a link cannot
be turned into it, nor into a link for another alert or a later expiry.

:func:`verify` answers one :class:`Verdict`, comparing signatures in constant time.
"""

from __future__ import annotations

import enum
import hashlib
import hmac
from urllib.parse import quote

_PURPOSE = b"frog-bt acknowledgement links v1"


class Verdict(enum.Enum):
    VALID = "valid"
    EXPIRED = "expired"
    BAD = "bad"  # malformed, tampered with, or signed for another alert


def link_key(token: str) -> bytes:
    """The signing key of ack links, derived from the console's token (HMAC as a KDF)."""
    return hmac.new(token.encode(), _PURPOSE, hashlib.sha256).digest()


def signature(key: bytes, alert_id: str, exp: int) -> str:
    """HMAC-SHA256 over the alert id and the expiry (separated: neither can borrow from
    the other), as hex."""
    message = alert_id.encode() + b"\x00" + str(exp).encode()
    return hmac.new(key, message, hashlib.sha256).hexdigest()


def ack_link(console_url: str, key: bytes, alert_id: str, exp: int) -> str:
    """The link that acknowledges ``alert_id`` until ``exp`` (epoch seconds)."""
    return (
        f"{console_url.rstrip('/')}/ack/{quote(alert_id, safe='')}"
        f"?exp={exp}&sig={signature(key, alert_id, exp)}"
    )


def verify(key: bytes, alert_id: str, exp: str, sig: str, now: float) -> Verdict:
    """Whether ``sig`` signs ``alert_id`` until ``exp``, and ``exp`` is still ahead of
    ``now`` (epoch seconds). The signature is checked first, in constant time; only a
    genuine link is told that it expired."""
    if not exp.isascii() or not exp.isdigit() or len(exp) > 12:
        return Verdict.BAD
    expected = signature(key, alert_id, int(exp))
    if not hmac.compare_digest(expected.encode(), sig.encode("utf-8", "replace")):
        return Verdict.BAD
    return Verdict.VALID if now < int(exp) else Verdict.EXPIRED
