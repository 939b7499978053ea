"""Where telemetry goes: the ``--rerun SPEC`` value, parsed and checked (no rerun here).

=====================  ==================================================================
``spawn``              start a rerun viewer (or reuse the one on port 9876) and stream to it
``save:FILE.rrd``      write a recording file (``rerun FILE.rrd`` opens it)
``connect[:URL]``      stream to a running viewer; URL default ``rerun+http://127.0.0.1:9876/proxy``
``serve[:PORT]``       host a gRPC server on 127.0.0.1 (default port 9876) that viewers connect to
=====================  ==================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_URL = "rerun+http://127.0.0.1:9876/proxy"
DEFAULT_PORT = 9876
URL_SCHEMES = ("rerun://", "rerun+http://", "rerun+https://")
EXPECTED = "expected spawn, save:FILE.rrd, connect[:URL] or serve[:PORT]"


@dataclass(frozen=True, slots=True)
class Sink:
    """A parsed spec: ``kind`` is spawn, save, connect or serve; ``target`` its argument."""

    kind: str
    target: str = ""
    port: int = DEFAULT_PORT


def parse_spec(spec: str) -> Sink:
    """The sink for ``spec``; ValueError saying what was expected otherwise."""
    if not isinstance(spec, str):
        raise ValueError(f"rerun telemetry spec {spec!r}: {EXPECTED}")
    kind, sep, arg = spec.strip().partition(":")
    if kind == "spawn" and not sep:
        return Sink("spawn")
    if kind == "save":
        if not arg.strip():
            raise ValueError(f"rerun telemetry spec {spec!r}: save needs a file, save:FILE.rrd")
        if not arg.endswith(".rrd"):
            raise ValueError(f"rerun telemetry spec {spec!r}: the file should end in .rrd")
        return Sink("save", arg)
    if kind == "connect":
        url = arg or DEFAULT_URL
        if not url.startswith(URL_SCHEMES) or not url.rstrip("/").endswith("/proxy"):
            raise ValueError(f"rerun telemetry spec {spec!r}: expected a URL like {DEFAULT_URL}")
        return Sink("connect", url)
    if kind == "serve":
        if not sep:
            return Sink("serve")
        if not arg.isdigit() or not 0 < int(arg) < 65536:
            raise ValueError(
                f"rerun telemetry spec {spec!r}: expected serve or serve:PORT (1-65535)"
            )
        return Sink("serve", port=int(arg))
    raise ValueError(f"rerun telemetry spec {spec!r}: {EXPECTED}")
