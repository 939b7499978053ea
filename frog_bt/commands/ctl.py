"""Send one operator command to a running executive's console, and print its answer.

    frog-bt ctl home|skip|pause|resume|service_off|service_on|retry|done_by_hand
    frog-bt ctl ack_alert ID
    frog-bt ctl status [--json]
    frog-bt ctl pair NAME | devices | unpair NAME
    [--console PORT|:PORT|HOST:PORT|URL] [--token-file F] [--timeout S]

``--console`` (or ``FROG_BT_CONSOLE``) is what ``run --console`` was given (``8080``,
``:8080``, ``0.0.0.0:8080``: a wildcard address is reached on loopback) or the console's
URL (``http://frog:8080``, behind a proxy ``https://...``); default ``127.0.0.1:8080``.
``status`` prints the robot's state as plain lines in the site's words; ``--json``, the
state as the console gives it. ``pair NAME`` prints the QR code of a one-time link that
pairs a staff phone called NAME (``staff.pairing_ttl``), ``devices`` lists the paired
ones, ``unpair NAME`` revokes one at once (all three with the staff token).

Exit 0 when the command was applied (``status``: the state was read), 1 when the tour
refused it (the reason is printed), 2 for a usage error, when the console cannot be
reached (within ``--timeout`` seconds) or when its answer is not a clear yes: only
``{"ok": true}`` counts as done. With a token, the answer must be the console's own: it
carries the console's identity (``X-Frog-Console``, derived from the token, as
``/api/state`` shows it) and the proof, over this request's nonce and the answer's body,
that the console holding the token wrote it (``X-Frog-Proof``). Redirects are never
followed (the token would go with the request to wherever the redirect points), no proxy
is ever used (``http_proxy`` and its kin are ignored), and the token does not go over
plain http to a host that is not loopback unless ``--insecure`` (with a warning). Output
into a closed pipe (``| head -1``) ends quietly.
"""

from __future__ import annotations

import argparse
import hmac
import json
import os
import secrets
import sys
import urllib.error
import urllib.parse
import urllib.request
from email.message import Message
from pathlib import Path
from typing import Any

from frog_bt import __version__
from frog_bt.commands.console_options import console_address
from frog_bt.engine.operator import Command
from frog_bt.errors import UsageError
from frog_bt.i18n import N_, Msg, translator
from frog_bt.live.console import CTL_AGENT
from frog_bt.live.console.acklink import answer_proof, console_id
from frog_bt.live.console.origins import is_loopback
from frog_bt.text import escape

DEFAULT_CONSOLE = "127.0.0.1:8080"
ENV = "FROG_BT_CONSOLE"
WILDCARDS = {"0.0.0.0": "127.0.0.1", "::": "::1", "": "127.0.0.1"}  # listen-on-all: ask loopback
DEVICE_COMMANDS = ("pair", "devices", "unpair")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "command",
        choices=[*(c.value for c in Command), "status", *DEVICE_COMMANDS],
        help="what to do (status: print the robot's state; pair NAME, devices, unpair NAME: "
        "staff phones)",
    )
    p.add_argument(
        "id", nargs="?", help="with ack_alert: the alert's id; with pair and unpair: the name"
    )
    p.add_argument(
        "--console",
        metavar="ADDRESS",
        help="the console: PORT, :PORT, HOST:PORT (as run --console) or a URL "
        f"(default: ${ENV}, else {DEFAULT_CONSOLE})",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="with status: the state as JSON, as the console gives it",
    )
    p.add_argument(
        "--token-file",
        metavar="FILE",
        type=Path,
        help="the staff token (the console's --console-token-file)",
    )
    p.add_argument(
        "--timeout", type=float, default=10.0, help="seconds to wait for the answer (default: 10)"
    )
    p.add_argument(
        "--insecure",
        action="store_true",
        help="send the token over plain http to a host that is not loopback (in clear: "
        "anyone on the way reads it; prefer https:// through a TLS proxy)",
    )


class NoRedirects(urllib.request.HTTPRedirectHandler):
    """A redirect is an answer (an error), not a place to send the token to."""

    def redirect_request(self, *_args: object, **_kwargs: object) -> None:
        return None


# no proxy, whatever http_proxy and its kin say: the token goes to the console named and
# nowhere else, and only the console's own answer counts
OPENER = urllib.request.build_opener(urllib.request.ProxyHandler({}), NoRedirects)


def _reason(body: bytes, default: str) -> str:
    try:
        answer = json.loads(body)
    except (ValueError, RecursionError):
        return default
    reason = answer.get("reason") if isinstance(answer, dict) else None
    return str(reason)[:300] if reason else default


def _fail(text: str) -> int:
    print(f"frog-bt ctl: {escape(text)}", file=sys.stderr)
    return 2


def console_url(text: str | None) -> str:
    """The console's base URL from what ``--console`` or ``FROG_BT_CONSOLE`` says:
    a URL as it is, ``PORT``, ``:PORT`` or ``HOST:PORT`` as ``run --console`` reads them
    (a wildcard host reached on loopback); UsageError when it is none of those."""
    text = (text or "").strip() or DEFAULT_CONSOLE
    if "://" in text:
        url = urllib.parse.urlsplit(text)
        if url.scheme in ("ws", "wss"):
            raise UsageError(
                "--console",
                text,
                f"{url.scheme}:// is the console's stream, not its address: give "
                f"{'https' if url.scheme == 'wss' else 'http'}://{url.netloc}",
            )
        if url.scheme not in ("http", "https") or not url.netloc:
            raise UsageError("--console", text, "expected http://HOST:PORT or https://HOST")
        path = url.path + "/"  # a page's or an API's address: the console's is above /api/
        path = path[: path.index("/api/")] if "/api/" in path else url.path
        return urllib.parse.urlunsplit((url.scheme, url.netloc, path.rstrip("/"), "", ""))
    if ":" not in text.rstrip("/") and not text.isdigit():  # a bare host: the default port
        text = f"{text.rstrip('/')}:{DEFAULT_CONSOLE.rpartition(':')[2]}"
    host, port = console_address(text.rstrip("/"))
    host = WILDCARDS.get(host, host)
    return f"http://[{host}]:{port}" if ":" in host else f"http://{host}:{port}"


def _in_clear(base: str, insecure: bool) -> str | None:
    """Why the token may not go to ``base``: plain http to a host that is not loopback,
    unless ``--insecure`` (then a warning names it); None when it may."""
    url = urllib.parse.urlsplit(base)
    if url.scheme != "http" or is_loopback(url.hostname or ""):
        return None
    if not insecure:
        return (
            f"{base} is plain http to a host that is not loopback: the token would travel "
            "in clear; use https:// (a TLS proxy in front, docs/CONSOLE.md) or give --insecure"
        )
    print(
        "frog-bt ctl: warning: --insecure: the token goes in clear over plain http to "
        f"{url.hostname}",
        file=sys.stderr,
    )
    return None


def _stranger(
    token: str | None, sent: dict[str, str], headers: Message | None, body: bytes, base: str
) -> str | None:
    """Why an answer is not the console's own (None when it is, or when there is no token
    to know it by): it must carry the console's identity (``X-Frog-Console``, derived from
    the token) and the proof that this body answers this request (``X-Frog-Proof``)."""
    if token is None:
        return None
    expected = console_id(token)
    got = headers.get("X-Frog-Console", "") if headers is not None else ""
    proof = headers.get("X-Frog-Proof", "") if headers is not None else ""
    if not hmac.compare_digest(got.encode(), expected.encode()):
        return (
            f"the answer from {base} is not from the console that holds this token "
            f"(console id {got[:32] or 'missing'}, expected {expected}): "
            "nothing is known to be done"
        )
    if not hmac.compare_digest(
        proof.encode(), answer_proof(token, sent["X-Frog-Nonce"], body).encode()
    ):
        return (
            f"the answer from {base} carries no valid proof of the console: "
            "nothing is known to be done"
        )
    return None


def run(args: argparse.Namespace) -> int:
    try:
        return _run(args)
    except BrokenPipeError:  # `frog-bt ctl status | head -1`: the reader has gone
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # the interpreter's last flush goes nowhere
        return 0


def _say(text: str) -> None:
    """Print ``text``, its lines as we made them, any other control character (robot
    text in a state or an answer) escaped."""
    print("\n".join(escape(line) for line in text.split("\n")))
    sys.stdout.flush()  # a closed pipe shows here, where it is caught


def _run(args: argparse.Namespace) -> int:
    given = args.console if args.console is not None else os.environ.get(ENV)
    try:
        base = console_url(given)
    except UsageError as exc:
        where = "--console" if args.console is not None else ENV
        hint = "" if "://" in (given or "") else ", or a URL"
        return _fail(f"{where} {given}: {exc.detail}{hint}")
    headers = {"Content-Type": "application/json", "User-Agent": f"{CTL_AGENT}/{__version__}"}
    token: str | None = None
    if args.token_file is not None:
        try:
            token = args.token_file.read_text("utf-8").strip()
        except (OSError, UnicodeDecodeError) as exc:
            return _fail(
                f"--token-file {args.token_file}: cannot read it: "
                f"{getattr(exc, 'strerror', None) or exc}"
            )
        problem = _in_clear(base, args.insecure)
        if problem:
            return _fail(problem)
        headers["Authorization"] = f"Bearer {token}"
        headers["X-Frog-Nonce"] = secrets.token_urlsafe(24)
    if args.command == "ack_alert" and not args.id:
        return _fail("ack_alert needs the alert's id (frog-bt ctl status lists them)")
    if args.command in ("pair", "unpair") and not args.id:
        return _fail(f"{args.command} needs the device's name, e.g. \"Lucía's phone\"")
    if args.command == "status":
        request = urllib.request.Request(f"{base}/api/state", headers=headers)
    elif args.command == "devices":
        request = urllib.request.Request(f"{base}/api/devices", headers=headers)
    elif args.command in ("pair", "unpair"):
        request = urllib.request.Request(
            f"{base}/api/{args.command}",
            method="POST",
            data=json.dumps({"name": args.id}).encode(),
            headers=headers,
        )
    else:
        body = {"command": args.command, **({"id": args.id} if args.id else {})}
        request = urllib.request.Request(
            f"{base}/api/command", method="POST", data=json.dumps(body).encode(), headers=headers
        )
    try:
        with OPENER.open(request, timeout=args.timeout) as response:
            raw = response.read(1_000_000)
            answered = response.headers
    except urllib.error.HTTPError as exc:
        if 300 <= exc.code < 400:
            where = exc.headers.get("Location", "?") if exc.headers else "?"
            return _fail(f"{exc.code}: the console redirects to {where[:200]}: not followed")
        said = exc.read(4096)
        reason = _reason(said, str(exc.reason))
        if exc.code == 409:
            stranger = _stranger(token, headers, exc.headers, said, base)
            if stranger:
                return _fail(stranger)
            _say(_in_words(N_("refused: {why}"), said, why=reason))
            return 1
        return _fail(f"{exc.code}: {reason}")
    except (urllib.error.URLError, OSError, ValueError) as exc:
        why = exc.reason if isinstance(exc, urllib.error.URLError) else exc
        return _fail(f"cannot reach the console at {base}: {why}")
    stranger = _stranger(token, headers, answered, raw, base)
    if stranger:
        return _fail(stranger)
    try:
        answer = json.loads(raw)
    except (ValueError, RecursionError):
        return _fail(f"the console's answer is not JSON: {raw[:80]!r}")
    if args.command == "status":
        if not isinstance(answer, dict) or "phase" not in answer:
            return _fail('the console\'s answer is not a state (no "phase")')
        if args.json:
            _say(json.dumps(answer, indent=1))
        else:
            _say("\n".join(state_lines(answer)))
        return 0
    if not isinstance(answer, dict) or answer.get("ok") is not True:
        reason = _reason(raw, "no reason given")
        if isinstance(answer, dict) and answer.get("ok") is False:
            _say(_in_words(N_("refused: {why}"), raw, why=reason))
            return 1
        return _fail(f'the console did not say "ok": true (so nothing was done): {raw[:80]!r}')
    if args.command == "pair":
        return _paired(answer, raw)
    if args.command == "devices":
        lang = answer.get("language")
        _say(
            "\n".join(
                device_lines(answer.get("devices", []), lang if isinstance(lang, str) else None)
            )
        )
        return 0
    _say(_in_words(N_("done: {what}"), raw, what=answer.get("did", "")))
    return 0


def _paired(answer: dict[str, Any], raw: bytes) -> int:
    """The pairing link as a QR code for the phone to scan, and as text."""
    link = str(answer.get("link", ""))
    minutes = round(float(answer.get("expires_in", 0)) / 60)
    try:
        from frog_bt.live.console.qr import terminal

        print(terminal(link), end="")
    except ImportError:  # no segno here: the link alone, to open on the phone
        print("frog-bt ctl: no QR code (segno is missing: pip install segno)", file=sys.stderr)
    _say(link)
    _say(
        _in_words(N_("scan this code with the phone within {m} min; it works once"), raw, m=minutes)
    )
    return 0


def device_lines(devices: list[Any], lang: str | None = None) -> list[str]:
    """A heading, then one line per paired device: its name, when it was paired and last
    seen (local time), tab-separated."""
    from datetime import datetime

    from frog_bt.clock import SITE_TZ

    def when(t: object) -> str:
        if not isinstance(t, int | float):
            return "-"
        return datetime.fromtimestamp(t, SITE_TZ).strftime("%Y-%m-%d %H:%M")

    words = translator(lang)
    heading = "\t".join(Msg(w).say(words) for w in (N_("Device"), N_("Paired"), N_("Last seen")))
    if not devices:
        return [Msg(N_("No device is paired.")).say(words)]
    return [heading] + [
        "\t".join(
            (
                escape(str(d.get("name", "")))[:64],
                when(d.get("paired_at")),
                when(d.get("last_seen")),
            )
        )
        for d in devices
        if isinstance(d, dict)
    ]


def _in_words(msgid: str, body: bytes, **args: Any) -> str:
    """``msgid`` in the language the console answered in (its answer's ``language``)."""
    try:
        answer = json.loads(body)
    except (ValueError, RecursionError):
        answer = None
    lang = answer.get("language") if isinstance(answer, dict) else None
    return Msg(msgid, **args).say(translator(lang if isinstance(lang, str) else None))


# ------------------------------------------------------------------ status, in words

LINKS = {"rosbridge": N_("The robot"), "frontend": N_("Screen and sound"), "clock": N_("Clock")}
LINK_STATES = {
    "connected": N_("connected"),
    "reconnecting": N_("reconnecting"),
    "connecting": N_("connecting"),
    "closed": N_("closed"),
    "acking": N_("answering"),
    "not heard": N_("not heard yet"),
    "silent": N_("silent"),
    "wall": N_("wall clock"),
    "/clock": N_("simulated clock"),
    "waiting for /clock": N_("waiting for the clock"),
}
DAY = (
    ("started", N_("Tours started")),
    ("completed", N_("Completed")),
    ("aborted", N_("Ended early")),
)


def state_lines(state: dict[str, Any]) -> list[str]:
    """The console's state as plain lines, in the site's words (``state["language"]``):
    what the robot is doing, the stop, the battery, what staff decided, a person needed,
    alerts, connections and the day so far."""
    words = translator(state.get("language"))

    def w(msgid: str, **args: Any) -> str:
        return Msg(msgid, **args).say(words)

    def field(label: str, value: object) -> str:
        return f"{w(label)}: {value}"

    def duration(seconds: object) -> str:
        s = max(0, round(float(seconds))) if isinstance(seconds, int | float) else 0
        return w(N_("{s} s"), s=s) if s < 90 else w(N_("{m} min {s} s"), m=s // 60, s=s % 60)

    out = [str(state.get("doing") or state.get("phase") or "")]
    if state.get("stop_name"):
        stop = state["stop_name"]
    else:
        stop = w(N_("looking for a visitor")) if state.get("touring") else w(N_("no tour now"))
    out.append(field(N_("Stop"), stop))
    if state.get("next_stop_name"):
        out.append(field(N_("Next stop"), state["next_stop_name"]))
    if state.get("stop_name") and state.get("at_stop_s") is not None:
        out.append(field(N_("Time at this stop"), duration(state["at_stop_s"])))
    if state.get("battery") is not None:
        out.append(field(N_("Battery"), f"{round(state['battery'])} %"))
    if state.get("paused"):
        out.append(w(N_("Paused")))
    if state.get("in_service") is False:
        out.append(w(N_("Out of service")))
    help_ = state.get("help")
    if isinstance(help_, dict):
        out.append(field(N_("The robot is waiting for a person"), help_.get("what", "")))
        if help_.get("by_hand"):
            out.append(f"  {field(N_('Done'), help_['by_hand'])}")
        answers = " | ".join(f"frog-bt ctl {a}" for a in help_.get("answers", []))
        out.append("  " + Msg("Answer with: {commands}", commands=answers).say(words))
    for alert in [*state.get("alerts", []), *state.get("cleared", [])]:
        raised = alert.get("state") == "raised"
        label = N_("The robot needs help") if raised else N_("Solved")
        out.append(field(label, alert.get("text", "")))
        seen = Msg("mark it seen: frog-bt ctl ack_alert {id}", id=alert.get("id", ""))
        out.append("  " + seen.say(words))
    for alert in state.get("holding", []):
        out.append(field(N_("Still true"), alert.get("text", "")))
    since = state.get("links_for_s", {})
    links = [
        f"{w(LINKS.get(name, name))} {w(LINK_STATES.get(st, st))} ({duration(since.get(name))})"
        for name, st in state.get("links", {}).items()
    ]
    out.append(field(N_("Connections"), ", ".join(links)))
    tours, day = state.get("tours", {}), state.get("day", {})
    counts = [f"{w(label)} {tours.get(key, 0)}" for key, label in DAY]
    counts += [f"{w(N_('Visitors'))} {day.get('visitors', 0)}"]
    counts += [f"{w(N_('Stops skipped'))} {day.get('skipped', 0)}"]
    out.append(field(N_("The day so far"), ", ".join(counts)))
    out += [f"  {line}" for line in day.get("last", [])]
    return out
