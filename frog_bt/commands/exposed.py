"""Secrets in files others can read: the site configuration when it holds webhook
credentials (a password in a URL, a key in its query, an ntfy topic, which is its own
secret), and the rosbridge secret file it names. One line each, with the fix; ``check``
and ``run`` say them, and go on."""

from __future__ import annotations

import shlex
import stat
from pathlib import Path
from urllib.parse import urlsplit

from frog_bt.config import Site

OTHERS = stat.S_IRGRP | stat.S_IROTH  # anyone but the owner may read it


def webhook_secrets(site: Site) -> bool:
    """Whether any destination of ``alerts.webhooks`` carries a secret in its URL."""
    for hook in site.alerts.webhooks:
        url = urlsplit(hook.url)
        if url.username or url.password or url.query or hook.format == "ntfy":
            return True
    return False


def _readable(path: Path) -> bool:
    try:
        return bool(path.stat().st_mode & OTHERS)
    except OSError:
        return False


def exposed(config: Path | None, site: Site) -> list[str]:
    """One line per secret in a file that others than its owner can read."""
    out = []
    if config is not None and webhook_secrets(site) and _readable(config):
        out.append(
            f"{config}: holds webhook credentials and others than its owner can read it; "
            f"fix: chmod 600 {shlex.quote(str(config))}"
        )
    secret_file = site.links.secret_file
    if secret_file and _readable(Path(secret_file)):
        out.append(
            f"{secret_file} (links.secret_file): others than its owner can read it; "
            f"fix: chmod 600 {shlex.quote(secret_file)}"
        )
    return out
