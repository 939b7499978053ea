"""The console's own origins: the ``Host`` a request names and the ``Origin`` a browser
sends must be the console's, or the request gets 403 (CONTRACT §7).

A page served from anywhere else (another site, another loopback port) cannot read the
stream or send commands, and a name rebound to the robot's address (DNS rebinding) is
not answered at all. The console's names are: the address it listens on with its port;
on loopback also ``127.0.0.1``, ``localhost`` and ``[::1]`` with the port; the address a
connection actually reached (a console on ``0.0.0.0`` answers to each of its own
addresses); the machine's host name with the port; and the host of
``alerts.console_url`` (the name phones and a TLS proxy in front use).
"""

from __future__ import annotations

import ipaddress
import socket
from dataclasses import dataclass, field
from urllib.parse import urlsplit

LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1")
DEFAULT_PORTS = {"http": 80, "https": 443, "ws": 80, "wss": 443}
Place = tuple[str, int]  # (lower-case host name or address without brackets, port)


def is_loopback(host: str) -> bool:
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def is_any(host: str) -> bool:
    """Whether ``host`` is a wildcard address (listening on every interface)."""
    return host.strip("[]") in ("", "0.0.0.0", "::")


def split_host(value: str) -> tuple[str, int | None] | None:
    """``Host`` header text as (name, port or None); None when it is not a host."""
    value = value.strip().lower()
    if not value or any(c in value for c in "/\\@ \t") or not value.isascii():
        return None
    if value.startswith("["):
        name, bracket, rest = value[1:].partition("]")
        if not bracket or (rest and not rest.startswith(":")):
            return None
        port_text = rest[1:]
    else:
        name, _, port_text = value.partition(":")
        if ":" in port_text:
            return None
    if not name:
        return None
    if not port_text:
        return name, None
    if not port_text.isdigit() or len(port_text) > 5:
        return None
    return name, int(port_text)


@dataclass
class Origins:
    """The console's places, set once it is bound (:meth:`bound`)."""

    host: str
    console_url: str = ""
    places: set[Place] = field(default_factory=set)
    port: int = 0

    def bound(self, port: int) -> None:
        """Listening on ``port``: its names with that port are the console's."""
        self.port = port
        names = {self.host.strip("[]").lower()} - {"", "0.0.0.0", "::"}
        if is_loopback(self.host) or is_any(self.host):
            names.update(LOOPBACK_NAMES)
        if is_any(self.host):
            names.add(socket.gethostname().lower())
        self.places = {(name, port) for name in names}
        if self.console_url:
            url = urlsplit(self.console_url)
            if url.hostname:
                self.places.add((url.hostname.lower(), url.port or DEFAULT_PORTS[url.scheme]))

    def host_ok(self, header: str | None, reached: str | None) -> bool:
        """Whether a request's ``Host`` names this console (``reached``: the local address
        the connection came in on). A missing ``Host`` is not a browser's: accepted."""
        if header is None:
            return True
        parsed = split_host(header)
        if parsed is None:
            return False
        name, port = parsed
        ports = (port,) if port is not None else (80, 443)
        places = self.places
        if reached is not None:
            places = places | {(reached.lower(), self.port)}
        return any((name, p) in places for p in ports)

    def origin_ok(self, header: str | None, reached: str | None) -> bool:
        """Whether a browser's ``Origin`` is this console's own page. Absent: not a
        browser (``ctl``, scripts): accepted. ``null`` (a sandbox, a file): refused."""
        if header is None:
            return True
        url = urlsplit(header.strip())
        if url.scheme not in ("http", "https") or url.path or url.query or not url.netloc:
            return False
        try:
            port = url.port or DEFAULT_PORTS[url.scheme]
        except ValueError:
            return False
        netloc = url.netloc.rsplit("@", 1)[-1]
        if "@" in url.netloc:
            return False
        name = split_host(netloc)
        if name is None:
            return False
        places = self.places
        if reached is not None:
            places = places | {(reached.lower(), self.port)}
        return (name[0], port) in places
