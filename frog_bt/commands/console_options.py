"""``--console HOST:PORT`` and ``--console-token-file FILE`` (run and demo, CONTRACT §5):
checked up front, and the console started and stopped around the executive."""

from __future__ import annotations

import argparse
import logging
import stat
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from frog_bt.config import parse_hostport
from frog_bt.errors import UsageError

if TYPE_CHECKING:
    from frog_bt.live.console.server import Console
    from frog_bt.live.console.webhooks import Webhooks
    from frog_bt.runtime.executive import Executive

DEFAULT_HOST = "127.0.0.1"
TOKEN_LENGTH = (16, 512)  # characters: long enough to guess at no rate, short enough for a header
log = logging.getLogger(__name__)


def add_console_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--console",
        metavar="HOST:PORT",
        help="serve the operator's console (HTTP; PORT alone: on 127.0.0.1)",
    )
    p.add_argument(
        "--console-token-file",
        metavar="FILE",
        type=Path,
        help="the staff token for commands (required off loopback)",
    )


@dataclass(frozen=True, slots=True)
class ConsoleSettings:
    host: str
    port: int
    token: str | None
    token_file: Path | None = None  # paired devices are kept beside it


def devices_file(settings: ConsoleSettings, configured: str | None) -> Path | None:
    """Where the paired devices are kept: ``staff.devices_file``, else beside the token
    file (``<token file>.devices``); None without a token (pairing is off)."""
    if settings.token is None:
        return None
    if configured:
        return Path(configured)
    if settings.token_file is None:
        return None
    return settings.token_file.with_name(settings.token_file.name + ".devices")


def console_settings(args: argparse.Namespace) -> ConsoleSettings | None:
    """The console's address and token, checked: UsageError (one line) for a bad address, a
    token file that cannot be read or is empty, or a non-loopback address without one."""
    if not args.console:
        if args.console_token_file is not None:
            raise UsageError(
                "--console-token-file", args.console_token_file, "given without --console"
            )
        return None
    try:
        from frog_bt.live.console.server import is_loopback
    except ImportError as exc:
        raise UsageError(
            "--console",
            args.console,
            f"needs the console extra ({exc.name} is missing): "
            "pip install -e '.[console]' from a checkout",
        ) from None

    host, port = console_address(str(args.console))
    token = read_token(args.console_token_file) if args.console_token_file is not None else None
    if token is None and not is_loopback(host):
        raise UsageError(
            "--console",
            args.console,
            f"{host} is not loopback: anyone on the "
            "network could steer the robot; give --console-token-file",
        )
    return ConsoleSettings(host, port, token, args.console_token_file)


def console_address(text: str, what: str = "--console") -> tuple[str, int]:
    """``PORT``, ``:PORT`` (both on 127.0.0.1) or ``HOST:PORT`` as (host, port);
    UsageError naming ``what`` when malformed."""
    if text.isdigit() or text.startswith(":"):
        text = f"{DEFAULT_HOST}:{text.lstrip(':')}"
    return parse_hostport(text, what)


def read_token(path: Path) -> str:
    """The staff token in ``path``: visible ASCII (it goes into a header), 16 to 512
    characters, else UsageError. A file that others than its owner can read or write is
    used, with a warning that says the fix in one line."""
    try:
        token = path.read_text(encoding="utf-8").strip()
        mode = path.stat().st_mode
    except (OSError, UnicodeDecodeError) as exc:
        raise UsageError(
            "--console-token-file", path, f"cannot read it: {getattr(exc, 'strerror', None) or exc}"
        ) from None
    shortest, longest = TOKEN_LENGTH
    if not shortest <= len(token) <= longest:
        raise UsageError(
            "--console-token-file",
            path,
            f"expected a token of {shortest} to {longest} characters, found {len(token)}",
        )
    if not all("!" <= c <= "~" for c in token):
        raise UsageError(
            "--console-token-file",
            path,
            "expected a token of visible ASCII characters (no spaces; e.g. "
            "python3 -c 'import secrets; print(secrets.token_urlsafe(32))')",
        )
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        log.warning(
            "--console-token-file %s: others than its owner may read or change it; "
            "fix: chmod 600 %s",
            path,
            path,
        )
    return token


async def start_console(
    executive: Executive, settings: ConsoleSettings, webhooks: Webhooks | None = None
) -> Console:
    """The console for ``executive``, listening (its shift's handovers told to
    ``webhooks``); UsageError when the port cannot be bound."""
    from frog_bt.live.console.devices import Devices
    from frog_bt.live.console.server import Console

    console = Console(
        executive,
        settings.host,
        settings.port,
        settings.token,
        tell=webhooks.hand_over if webhooks is not None else None,
        devices=Devices(devices_file(settings, executive.site.staff.devices_file)),
    )
    console.attach()
    try:
        await console.start()
    except OSError as exc:
        await console.close()
        raise UsageError(
            "--console",
            f"{settings.host}:{settings.port}",
            f"cannot listen there: {exc.strerror or exc}",
        ) from None
    return console


@dataclass
class People:
    """What is started for the people around the robot: the console (if asked for) and
    the webhooks, with the alerts told to them and to the recorders."""

    console: Console | None
    webhooks: Webhooks

    async def close(self, deliver: bool = False) -> None:
        """Stop the console, then the webhooks: within a second, or (``deliver``: the
        executive stops because the robot needs help, CONTRACT §5) once every alert is
        delivered or its delivery has run out of attempts."""
        if self.console is not None:
            await self.console.close()
        cfg = self.webhooks.cfg
        attempts_budget = cfg.webhook_attempts * cfg.webhook_timeout + cfg.webhook_backoff * (
            2 ** max(0, cfg.webhook_attempts - 1)
        )
        await self.webhooks.finish(attempts_budget + 1.0 if deliver else 1.0)


async def start_people(
    executive: Executive, settings: ConsoleSettings | None, observers: Sequence[object]
) -> People:
    from frog_bt.live.console.webhooks import Webhooks
    from frog_bt.runtime import logctx

    webhooks = Webhooks(
        executive.site.alerts,  # its ack links' key comes from the token
        ack_secret=settings.token if settings is not None else None,
        language=executive.site.language,
        tz=executive.clock.tz,
    )
    executive.observers.attach(executive, [webhooks])  # every alert change
    logctx.run_as(executive, webhooks.start)  # its lines are the executive's (console log)
    console = await start_console(executive, settings, webhooks) if settings is not None else None
    return People(console, webhooks)
