"""Staff phones paired once, each with its own key and a person's name for it.

* :class:`Pairings` — one-time pairing codes: ``frog-bt ctl pair NAME`` (or someone signed
  in on the page) asks for one; it is valid for ``staff.pairing_ttl`` seconds and for one
  claim. Only its hash is kept.
* :class:`Devices` — the paired devices: a name ("Lucía's phone"), the SHA-256 of its key,
  when it was paired and last seen. Kept in a JSON file beside the console's token file
  (``<token file>.devices``, or ``staff.devices_file``), written 0600 and replaced whole.
  A key is 43 random URL-safe characters (256 bits), sent as ``Authorization: Bearer
  KEY``; it is looked up by its hash, compared in constant time against every device,
  bounded in length, never logged, never in a URL. Unpairing removes it at once: its next
  request gets 401.

Clocks are passed in (wall seconds by default), so tests move time by hand.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import json
import logging
import os
import secrets
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

from frog_bt.i18n import Msg
from frog_bt.text import is_inert

__all__ = ["Device", "Devices", "Pairings", "name_problem"]

log = logging.getLogger(__name__)
Clock = Callable[[], float]
NAME_MAX = 64  # characters of a device's name
KEY_MAX = 128  # bytes of a key looked at (ours are 43)
MAX_DEVICES = 100
MAX_PAIRINGS = 16  # pairing codes waiting at once; the oldest go first
SEEN_EVERY = 60.0  # seconds: last_seen is written at most this often


def _digest(secret: bytes) -> str:
    return hashlib.sha256(b"frog-bt device:" + secret).hexdigest()


def name_problem(name: object) -> Msg | None:
    """Why ``name`` cannot name a device (None when it can): 1 to 64 characters of plain
    text, no control or format characters."""
    if not isinstance(name, str) or not name.strip():
        return Msg("a device needs a name, such as Lucía's phone")
    if len(name) > NAME_MAX or not is_inert(name):
        return Msg("a device's name is plain text of at most {n} characters", n=NAME_MAX)
    return None


@dataclass
class Device:
    name: str
    key_hash: str
    paired_at: float
    last_seen: float | None = None


@dataclass
class Pairings:
    """One-time pairing codes: :meth:`issue` one for a name, :meth:`claim` it once within
    ``ttl`` seconds."""

    ttl: float = 300.0
    clock: Clock = time.time
    waiting: OrderedDict[str, tuple[str, float]] = field(default_factory=OrderedDict)

    def issue(self, name: str) -> str:
        code = secrets.token_urlsafe(24)
        self.waiting[_digest(code.encode())] = (name, self.clock() + self.ttl)
        while len(self.waiting) > MAX_PAIRINGS:
            self.waiting.popitem(last=False)
        return code

    def claim(self, code: object) -> str | None:
        """The name ``code`` was issued for, when it is valid now; it is gone either way."""
        if not isinstance(code, str) or not code or len(code) > KEY_MAX:
            return None
        held = self.waiting.pop(_digest(code.encode("utf-8", "surrogateescape")), None)
        if held is None or self.clock() > held[1]:
            return None
        return held[0]


class Devices:
    """The paired devices of one console, kept in ``path`` (None: pairing is off)."""

    def __init__(self, path: Path | None, clock: Clock = time.time) -> None:
        self.path = path
        self.clock = clock
        self.devices: dict[str, Device] = {}
        self._written: dict[str, float] = {}  # name -> last_seen as last written
        if path is not None:
            self._load(path)

    def _load(self, path: Path) -> None:
        try:
            data = json.loads(path.read_text("utf-8"))
        except FileNotFoundError:
            return
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            # fail closed: no device is let in by a file that cannot be read
            log.warning("paired devices: cannot read %s (%s): none is paired", path, exc)
            return
        for item in data.get("devices", []) if isinstance(data, dict) else []:
            try:
                device = Device(**item)
            except TypeError:
                continue
            if name_problem(device.name) is None and len(device.key_hash) == 64:
                self.devices[device.name] = device

    def save(self) -> None:
        """Write the file whole, 0600 (OSError when it cannot be written)."""
        if self.path is None:
            raise OSError("pairing is off: the console has no token file")
        tmp = self.path.with_name(self.path.name + ".tmp")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump({"devices": [asdict(d) for d in self.devices.values()]}, f, indent=1)
        os.chmod(tmp, 0o600)
        os.replace(tmp, self.path)
        self._written = {d.name: d.last_seen or 0.0 for d in self.devices.values()}

    def pair(self, name: str) -> str:
        """A new device called ``name``: its key (shown to it once, kept hashed). ValueError
        when the name is taken or there are too many; OSError when it cannot be kept."""
        if name in self.devices:
            raise ValueError(f"a device called {name!r} is paired already: unpair it first")
        if len(self.devices) >= MAX_DEVICES:
            raise ValueError(f"{MAX_DEVICES} devices are paired: unpair one first")
        key = secrets.token_urlsafe(32)
        self.devices[name] = Device(name, _digest(key.encode()), self.clock())
        try:
            self.save()
        except OSError:
            del self.devices[name]
            raise
        return key

    def find(self, key: bytes | None) -> Device | None:
        """The device holding ``key``: its hash compared, in constant time, with every
        device's (no early exit)."""
        if not key or len(key) > KEY_MAX or not self.devices:
            return None
        digest = _digest(key).encode()
        found = None
        for device in self.devices.values():
            if hmac.compare_digest(digest, device.key_hash.encode()):
                found = device
        return found

    def seen(self, device: Device) -> None:
        """``device`` was used now (written at most every :data:`SEEN_EVERY` seconds)."""
        now = self.clock()
        device.last_seen = now
        if now - self._written.get(device.name, 0.0) >= SEEN_EVERY:
            with contextlib.suppress(OSError):  # a read-only disk costs the date, not the call
                self.save()

    def unpair(self, name: str) -> bool:
        """Revoke ``name`` at once (False when there is none)."""
        if self.devices.pop(name, None) is None:
            return False
        self.save()  # OSError: revoked now, but back after a restart: the caller says so
        return True

    def listed(self) -> list[dict[str, object]]:
        return [
            {"name": d.name, "paired_at": d.paired_at, "last_seen": d.last_seen}
            for d in sorted(self.devices.values(), key=lambda d: d.paired_at)
        ]
