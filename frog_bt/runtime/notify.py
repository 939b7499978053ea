"""systemd's notify protocol (sd_notify): READY, STATUS and the watchdog's pings.

One datagram per notification to the Unix socket in ``$NOTIFY_SOCKET`` (``@name`` is
Linux's abstract namespace). Without the variable (not started by systemd with
``Type=notify``), every call does nothing. ``$WATCHDOG_USEC`` (set by systemd when the
unit has ``WatchdogSec=``) gives the interval: a ping is sent at most every half of it,
from the executive's tick loop itself, so a loop that wedges stops the pings and systemd
restarts the executive (whose checkpoint then resumes the tour). ``STATUS=`` carries the
status line, at most once a second and only when it changed. Never raises: a missing
socket is logged once.
"""

from __future__ import annotations

import logging
import os
import socket
import time
from collections.abc import Callable, Mapping

log = logging.getLogger(__name__)
STATUS_EVERY = 1.0  # seconds between two STATUS= at most


class Notifier:
    def __init__(
        self,
        address: str | None,
        watchdog_usec: int | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.address = "\0" + address[1:] if address and address.startswith("@") else address
        self.ping_every = watchdog_usec / 2e6 if watchdog_usec else None
        self.clock = clock
        self._last_ping = -float("inf")
        self._last_status = ("", -float("inf"))
        self._socket: socket.socket | None = None
        self._failed = False
        self.dropped = 0  # notifications the receiver had no room for

    @classmethod
    def from_env(cls, env: Mapping[str, str] | None = None) -> Notifier:
        env = os.environ if env is None else env
        usec = env.get("WATCHDOG_USEC", "")
        pid = env.get("WATCHDOG_PID", "")
        if pid and pid != str(os.getpid()):
            usec = ""  # the watchdog is another process's
        return cls(env.get("NOTIFY_SOCKET") or None, int(usec) if usec.isdigit() else None)

    @property
    def enabled(self) -> bool:
        return self.address is not None

    def send(self, *fields: str) -> None:
        if self.address is None or self._failed:
            return
        try:
            if self._socket is None:
                self._socket = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
                self._socket.setblocking(False)
            self._socket.sendto("\n".join(fields).encode(), self.address)
        except BlockingIOError:
            self.dropped += 1  # systemd's queue is full for now: this one is lost, not all
        except OSError as exc:
            self._failed = True
            log.warning(
                "systemd notify socket %s: %s; not notifying any more",
                self.address.lstrip("\0"),
                exc.strerror or exc,
            )

    def ready(self, status: str = "") -> None:
        self.send("READY=1", *([f"STATUS={status}"] if status else []))

    def alive(self) -> None:
        """From the tick loop, at every turn: a watchdog ping when one is due."""
        if self.ping_every is None:
            return
        now = self.clock()
        if now - self._last_ping >= self.ping_every:
            self._last_ping = now
            self.send("WATCHDOG=1")

    def status(self, line: Callable[[], str]) -> None:
        """``STATUS=`` with ``line()`` if a second has passed and it changed."""
        if self.address is None:
            return
        text, at = self._last_status
        now = self.clock()
        if now - at < STATUS_EVERY:
            return
        new = line()[:200]
        self._last_status = (new, now)
        if new != text:
            self.send(f"STATUS={new}")

    def stopping(self) -> None:
        self.send("STOPPING=1")

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close()
            self._socket = None
