"""Signed links that acknowledge one raise of one alert of one robot, from a phone:
sans-I/O, no clock of its own.

A notification carries ``{console_url}/ack/{alert_id}?at=AT&exp=EXP&sig=SIG``. ``AT`` is
the alert's occurrence (:attr:`~frog_bt.model.channels.Alert.occurrence`: its raise time,
so a later raise of the same alert has another); ``EXP`` the wall-clock epoch second the
link expires (the phone's request comes in real time, so the project clock, simulated in
a rehearsal, is not the one to hold it against). ``SIG`` is HMAC-SHA256, hex, over the
robot's name (``alerts.robot``), the alert's id, ``AT`` and ``EXP``, under a key of its
own *derived* from the console's token (:func:`link_key`, HMAC as a KDF with a purpose of
its own): the token never leaves the executive, and a link teaches nothing about it, nor
makes a link for another robot, another alert, another raise or a later expiry.

:func:`verify` answers one :class:`Verdict`, comparing signatures in constant time. That a
link is used once, and only for the raise it names, is the console's to hold
(:mod:`~frog_bt.live.console.ackpage`).

:func:`console_id` is the console's public identity, derived from the token with another
purpose: ``frog-bt ctl``, which holds the same token, computes it too and refuses an
answer that does not carry it.
"""

from __future__ import annotations

import enum
import hashlib
import hmac
from urllib.parse import quote

_PURPOSE = b"frog-bt acknowledgement links v2"
_ID_PURPOSE = b"frog-bt console identity v1"
_PROOF_PURPOSE = b"frog-bt console answers v1"
MAX_OCCURRENCE = 32  # characters of ``at`` looked at


class Verdict(enum.Enum):
    VALID = "valid"
    EXPIRED = "expired"
    BAD = "bad"  # malformed, tampered with, or signed for another robot, alert or raise


def _derive(token: str, purpose: bytes) -> bytes:
    return hmac.new(token.encode(), purpose, hashlib.sha256).digest()


def link_key(token: str) -> bytes:
    """The signing key of ack links, derived from the console's token (HMAC as a KDF)."""
    return _derive(token, _PURPOSE)


def console_id(token: str) -> str:
    """The console's identity: public (on ``/api/state`` and in every answer's
    ``X-Frog-Console``), the same for whoever holds the token, and nothing about it."""
    return _derive(token, _ID_PURPOSE).hex()[:16]


def answer_proof(token: str, nonce: str, body: bytes) -> str:
    """What the console says about one answer to ``ctl``: HMAC over the request's nonce
    and the answer's body, under a key derived from the token (``X-Frog-Proof``)."""
    key = _derive(token, _PROOF_PURPOSE)
    return hmac.new(key, nonce.encode() + b"\x00" + body, hashlib.sha256).hexdigest()


def signature(key: bytes, robot: str, alert_id: str, at: str, exp: int) -> str:
    """HMAC-SHA256 over the robot, the alert id, its occurrence and the expiry (each
    length-prefixed: none can borrow from another), as hex."""
    parts = [p.encode("utf-8", "replace") for p in (robot, alert_id, at, str(exp))]
    message = b"".join(len(p).to_bytes(4, "big") + p for p in parts)
    return hmac.new(key, message, hashlib.sha256).hexdigest()


def ack_link(console_url: str, key: bytes, robot: str, alert_id: str, at: str, exp: int) -> str:
    """The link that acknowledges raise ``at`` of ``robot``'s ``alert_id`` until ``exp``
    (epoch seconds)."""
    sig = signature(key, robot, alert_id, at, exp)
    return (
        f"{console_url.rstrip('/')}/ack/{quote(alert_id, safe='')}"
        f"?at={quote(at, safe='')}&exp={exp}&sig={sig}"
    )


def verify(
    key: bytes, robot: str, alert_id: str, at: str, exp: str, sig: str, now: float
) -> Verdict:
    """Whether ``sig`` signs raise ``at`` of ``robot``'s ``alert_id`` until ``exp``, and
    ``exp`` is still ahead of ``now`` (epoch seconds). The signature is checked first, in
    constant time; only a genuine link is told that it expired."""
    if not exp.isascii() or not exp.isdigit() or len(exp) > 12 or len(at) > MAX_OCCURRENCE:
        return Verdict.BAD
    expected = signature(key, robot, alert_id, at, int(exp))
    if not hmac.compare_digest(expected.encode(), sig.encode("utf-8", "replace")):
        return Verdict.BAD
    return Verdict.VALID if now < int(exp) else Verdict.EXPIRED
