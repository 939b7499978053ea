"""Send one operator command to a running executive's console, and print its answer.

    frog-bt ctl home|skip|pause|resume|service_off|service_on [--console URL] [--token-file F]
    frog-bt ctl ack_alert ID
    frog-bt ctl status

Exit 0 when the command was applied (``status``: the state was read), 1 when the tour
refused it (the reason is printed), 2 for a usage error, when the console cannot be
reached (within ``--timeout`` seconds) or when its answer is not a clear yes: only
``{"ok": true}`` counts as done. Redirects are never followed (the token would go with
the request to wherever the redirect points).
"""

from __future__ import annotations

import argparse
import json
import sys
import urllib.error
import urllib.request
from pathlib import Path

from frog_bt.engine.operator import Command

DEFAULT_CONSOLE = "http://127.0.0.1:8080"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "command",
        choices=[*(c.value for c in Command), "status"],
        help="what to do (status: print the robot's state)",
    )
    p.add_argument("id", nargs="?", help="with ack_alert: the alert's id")
    p.add_argument(
        "--console",
        metavar="URL",
        default=DEFAULT_CONSOLE,
        help=f"the console's address (default: {DEFAULT_CONSOLE})",
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


class NoRedirects(urllib.request.HTTPRedirectHandler):
    """A redirect is an answer (an error), not a place to send the token to."""

    def redirect_request(self, *_args: object, **_kwargs: object) -> None:
        return None


OPENER = urllib.request.build_opener(NoRedirects)


def _reason(body: bytes, default: str) -> str:
    try:
        answer = json.loads(body)
    except (ValueError, RecursionError):
        return default
    reason = answer.get("reason") if isinstance(answer, dict) else None
    return str(reason)[:300] if reason else default


def _fail(text: str) -> int:
    print(f"frog-bt ctl: {text}", file=sys.stderr)
    return 2


def run(args: argparse.Namespace) -> int:
    base = args.console.rstrip("/")
    if "://" not in base:
        base = f"http://{base}"
    headers = {"Content-Type": "application/json"}
    if args.token_file is not None:
        try:
            headers["Authorization"] = "Bearer " + args.token_file.read_text("utf-8").strip()
        except (OSError, UnicodeDecodeError) as exc:
            return _fail(
                f"--token-file {args.token_file}: cannot read it: "
                f"{getattr(exc, 'strerror', None) or exc}"
            )
    if args.command == "ack_alert" and not args.id:
        return _fail("ack_alert needs the alert's id (frog-bt ctl status lists them)")
    if args.command == "status":
        request = urllib.request.Request(f"{base}/api/state", headers=headers)
    else:
        body = {"command": args.command, **({"id": args.id} if args.id else {})}
        request = urllib.request.Request(
            f"{base}/api/command", method="POST", data=json.dumps(body).encode(), headers=headers
        )
    try:
        with OPENER.open(request, timeout=args.timeout) as response:
            raw = response.read(1_000_000)
    except urllib.error.HTTPError as exc:
        if 300 <= exc.code < 400:
            where = exc.headers.get("Location", "?") if exc.headers else "?"
            return _fail(f"{exc.code}: the console redirects to {where[:200]}: not followed")
        reason = _reason(exc.read(4096), str(exc.reason))
        if exc.code == 409:
            print(f"refused: {reason}")
            return 1
        return _fail(f"{exc.code}: {reason}")
    except (urllib.error.URLError, OSError, ValueError) as exc:
        why = exc.reason if isinstance(exc, urllib.error.URLError) else exc
        return _fail(f"cannot reach the console at {base}: {why}")
    try:
        answer = json.loads(raw)
    except (ValueError, RecursionError):
        return _fail(f"the console's answer is not JSON: {raw[:80]!r}")
    if args.command == "status":
        if not isinstance(answer, dict) or "phase" not in answer:
            return _fail('the console\'s answer is not a state (no "phase")')
        print(json.dumps(answer, indent=1))
        return 0
    if not isinstance(answer, dict) or answer.get("ok") is not True:
        reason = _reason(raw, "no reason given")
        if isinstance(answer, dict) and answer.get("ok") is False:
            print(f"refused: {reason}")
            return 1
        return _fail(f'the console did not say "ok": true (so nothing was done): {raw[:80]!r}')
    print(f"done: {answer.get('did', '')}")
    return 0
