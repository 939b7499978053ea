"""Where each ``frog-bt run`` option comes from: the command line, else the environment
(``FROG_BT_ROSBRIDGE``, ``FROG_BT_SIM_TIME``, ...: ``FROG_BT_`` and the option's name in
capitals, dashes as underscores), else the site configuration's ``run:`` section, else
the default. ``--tree`` and ``--config`` can come from ``FROG_BT_TREE`` and
``FROG_BT_CONFIG`` (not from the site configuration, which they name).
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Mapping
from pathlib import Path

from frog_bt.config import RunCfg
from frog_bt.errors import UsageError

TRUE, FALSE = {"1", "true", "yes", "on"}, {"0", "false", "no", "off"}
PATHS = {"record", "checkpoint", "console_token_file"}


def env_name(option: str) -> str:
    return "FROG_BT_" + option.upper()


def _from_env(option: str, text: str, flag: bool) -> object:
    if not flag:
        return Path(text) if option in PATHS else text
    lowered = text.strip().lower()
    if lowered in TRUE or lowered in FALSE:
        return lowered in TRUE
    raise UsageError(env_name(option), text, "expected 1/true/yes/on or 0/false/no/off")


def tree_and_config(args: argparse.Namespace, env: Mapping[str, str] | None = None) -> None:
    env = os.environ if env is None else env
    for option in ("tree", "config"):
        if getattr(args, option, None) is None and env.get(env_name(option)):
            setattr(args, option, Path(env[env_name(option)]))


def fill(
    args: argparse.Namespace, run: RunCfg, env: Mapping[str, str] | None = None
) -> dict[str, str]:
    """Fill every option the command line left out (None) from the environment or
    ``run``; where each came from (``env``, ``site``), for the banner."""
    env = os.environ if env is None else env
    sources: dict[str, str] = {}
    for option in RunCfg.model_fields:
        if getattr(args, option, None) is not None:
            continue
        flag = RunCfg.model_fields[option].annotation == (bool | None)
        text = env.get(env_name(option))
        if text:
            setattr(args, option, _from_env(option, text, flag))
            sources[option] = "env"
            continue
        value = getattr(run, option)
        if value is not None:
            setattr(args, option, Path(value) if option in PATHS else value)
            sources[option] = "site"
    for option in ("sim_time", "once", "fresh", "watch", "quiet"):
        if getattr(args, option, None) is None:
            setattr(args, option, False)
    if getattr(args, "log_format", None) is None:
        args.log_format = "text"
    return sources
