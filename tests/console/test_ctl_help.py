"""``frog-bt ctl retry`` and ``done_by_hand`` (CONTRACT §7's answers to a robot that needs a
person), as a deployer types them."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from console_tour import TOKEN, console_tour

from frog_bt.cli import main
from frog_bt.model import keys
from frog_bt.model.events import OperatorDone
from frog_bt.runtime.observer import listen


def test_ctl_answers_a_robot_that_needs_help(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN + "\n")
    token.chmod(0o600)

    def ctl(*argv: str) -> tuple[int, str]:
        code = main(["ctl", *argv, "--token-file", str(token), "--timeout", "30"])
        return code, capsys.readouterr().out.strip()

    senders: list[tuple[str, str]] = []

    async def run() -> list[tuple[int, str]]:
        out = []
        async with console_tour({"docking": {"dock_failures": 3}}, once=False) as (
            tour,
            _people,
            url,
        ):
            exe = tour.executive
            listen(exe, lambda e: senders.append((e.command, e.by)), OperatorDone)
            out.append(await asyncio.to_thread(ctl, "retry", "--console", url))  # no help yet
            await tour.executive_ticks_until(lambda: exe.core.board.get(keys.HELP) is not None, 120)
            out.append(await asyncio.to_thread(ctl, "retry", "--console", url))
            await tour.executive_ticks_until(lambda: exe.core.board.get(keys.HELP) is None, 60)
            exe.stop("test over")
        return out

    before, retried = asyncio.run(run())
    # the site speaks Spanish
    assert before == (1, "no se ha hecho: ahora el robot no necesita ayuda")
    assert retried[0] == 0 and retried[1].startswith("hecho: lo vuelve a intentar")
    assert senders == [("retry", "ctl"), ("retry", "ctl")]  # recorded as sent by ctl
