"""``frog-bt ctl`` (CONTRACT §5) against a running console: exit 0 done, 1 refused, 2 usage
or connection error, each with its answer on one line."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from console_tour import TOKEN, console_tour
from test_faults import is_

from frog_bt.cli import main


def test_ctl_exit_codes_and_answers(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    token = tmp_path / "token"
    token.write_text(TOKEN + "\n")

    def ctl(*argv: str) -> int:
        return main(["ctl", *argv, "--token-file", str(token), "--timeout", "30"])

    async def run() -> list[tuple[int, str, str]]:
        out = []
        async with console_tour() as (tour, _people, url):
            await tour.sim.wait_for(is_("tour", state="started"), 60)
            # the robot undocking for simulated seconds that last as long in wall time:
            # no stop is under way yet while ctl asks (at 1000x the first could be)
            tour.sim.speed = 1.0
            for argv in (["skip", "--console", url], ["home", "--console", url]):
                code = await asyncio.to_thread(ctl, *argv)
                printed = capsys.readouterr()
                out.append((code, printed.out.strip(), printed.err.strip()))
            tour.sim.speed = 1000.0
            await tour.sim.wait_for(is_("tour", state="aborted"), 60)
            await tour.finish()
        return out

    refused, done = asyncio.run(run())
    # ctl answers in the site's language (config/site.yaml: es)
    assert refused == (
        1,
        "no se ha hecho: no está en ninguna parada ni yendo a una: no hay nada que saltar",
        "",
    )
    assert done == (
        0,
        "hecho: termina la visita: el robot vuelve a la base y se pone a cargar",
        "",
    )
    assert main(["ctl", "ack_alert"]) == 2
    assert "ack_alert needs the alert's id" in capsys.readouterr().err
    # nothing listens there: a connection error, bounded, exit 2
    assert main(["ctl", "home", "--console", "http://127.0.0.1:9", "--timeout", "5"]) == 2
    assert capsys.readouterr().err.startswith(
        "frog-bt ctl: cannot reach the console at http://127.0.0.1:9:"
    )
