"""Case 4: security of the links and of the definition files.

Outcomes:

* every listener binds a loopback address unless configured otherwise (site
  ``links``, ``frog-bt run``/``sim`` defaults, the simulator);
* UDP datagrams are accepted only from the configured front-end host (others
  dropped and counted; see also the flood in ``test_bad_input.py``);
* with a shared secret the executive sends the rosbridge ``auth`` op first on
  every connection; the secret comes from ``links.secret_env`` (default
  ``FROG_ROSBRIDGE_SECRET``) or ``links.secret_file``, and never appears in a log
  record or an exception; a server with another secret refuses the client, which
  keeps retrying (with backoff) without crashing;
* YAML is loaded safely: Python tags in a tree, site or scenario file are a
  clean definition error, nothing is executed; tree files can name only
  registered leaf types.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
from pathlib import Path
from urllib.parse import urlparse

import pytest
from harness import TourRun

from frog_bt.behaviours import load_tree
from frog_bt.cli import main
from frog_bt.commands.run import read_secret
from frog_bt.config import Links, load_site, parse_hostport
from frog_bt.errors import ConfigError, TreeError
from frog_bt.rosbridge.link import LinkState
from frog_bt.sim import Simulator, load_scenario

SECRET = "s3cret-FROG-7f1c2a9e"
WRONG = "wr0ng-FROG-41d0"


def loopback(host: str) -> bool:
    return ipaddress.ip_address(host).is_loopback


def leaks(caplog: pytest.LogCaptureFixture, *secrets: str) -> list[str]:
    """Log records (message, arguments, traceback) that contain any of ``secrets``."""
    out = []
    for record in caplog.records:
        text = f"{record.getMessage()} {record.args!r} {record.exc_text or ''}"
        if record.exc_info and record.exc_info[1] is not None:
            text += repr(record.exc_info[1])
        out += [text[:200] for s in secrets if s in text]
    return out


# ------------------------------------------------------------------ loopback by default


def test_every_listener_binds_loopback_by_default(capsys: pytest.CaptureFixture[str]) -> None:
    for links in (Links(), load_site().links):
        assert loopback(parse_hostport(links.listen)[0])  # the executive's UDP port
        assert loopback(parse_hostport(links.frontend)[0])
        assert loopback(urlparse(links.rosbridge).hostname or "")
    with pytest.raises(SystemExit):
        main(["sim", "--help"])
    text = " ".join(capsys.readouterr().out.split())  # help text is wrapped
    for default in ("default 127.0.0.1:9090", "default 127.0.0.1:5005", "default 127.0.0.1:5006"):
        assert default in text

    async def bound() -> dict[str, list[tuple[str, int]]]:
        sim = Simulator(load_scenario("default"), rosbridge_port=0, frontend_port=0)
        await sim.start(run_clock=False)
        try:
            return sim.addresses
        finally:
            await sim.stop()

    addresses = asyncio.run(bound())
    assert addresses["rosbridge"] and addresses["frontend"]
    assert all(loopback(host) for host, _ in addresses["rosbridge"] + addresses["frontend"])


def test_sim_command_defaults_are_loopback() -> None:
    import argparse

    from frog_bt.sim.command import add_arguments

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = parser.parse_args([])
    assert all(loopback(addr[0]) for addr in (args.rosbridge, args.frontend, args.executive))


# ------------------------------------------------------------------ rosbridge auth


def test_secret_from_the_environment_or_a_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    secret_file = tmp_path / "secret"
    secret_file.write_text(SECRET + "\n", encoding="utf-8")
    site = load_site().model_copy(update={"links": Links(secret_file=str(secret_file))})
    monkeypatch.delenv("FROG_ROSBRIDGE_SECRET", raising=False)
    assert read_secret(site) == SECRET
    monkeypatch.setenv("FROG_ROSBRIDGE_SECRET", WRONG)
    assert read_secret(site) == WRONG  # the environment first
    other = Links(secret_env="MY_SECRET")
    monkeypatch.setenv("MY_SECRET", SECRET)
    assert read_secret(site.model_copy(update={"links": other})) == SECRET
    assert read_secret(site.model_copy(update={"links": Links(secret_env="UNSET_X")})) is None


def test_tour_with_a_shared_secret_never_logs_it(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG)

    async def main() -> None:
        async with TourRun(secret=SECRET, sim_secret=SECRET) as run:
            await run.sim.wait_for(lambda r: r.channel == "/GotoWayPoint", 30)
            (client,) = run.sim.bridge.clients.values()
            assert client.authenticated
            outcome = await run.finish()
            assert outcome.code == 0, outcome.reason
            assert run.sim.bridge.stats.auth_failures == 0
            assert SECRET not in repr(run.executive.client.session)
            assert SECRET not in repr(vars(run.executive.client))

    asyncio.run(main())
    assert len(caplog.records) > 100  # DEBUG was on
    assert leaks(caplog, SECRET) == []


@pytest.mark.parametrize("secret", [WRONG, None], ids=["wrong secret", "no secret"])
def test_wrong_secret_is_refused_and_the_executive_keeps_trying(
    secret: str | None, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.DEBUG)

    async def main() -> None:
        async with TourRun(secret=secret, sim_secret=SECRET) as run:
            exe = run.executive
            for _ in range(2):  # refused, and refused again after the backoff
                await run.wait_event(
                    lambda e: isinstance(e, LinkState) and not e.connected, since=len(run.events)
                )
            assert not run.task.done()
            assert run.sim.bridge.stats.auth_failures >= 2
            assert run.sim.received(side="ros") == []  # not one op acted on
            assert run.sim.bridge.clients == {}
            assert not exe.clock.ready and exe.core.ticks == 0  # no /clock: nothing timed
            assert "1008" in (exe.client.link.last_error or "")
        assert run.task.result().code == 0  # stopped by the test, cleanly

    asyncio.run(main())
    assert leaks(caplog, SECRET, WRONG) == []
    # the executive says why, as a warning (rate-limited like every link warning)
    assert [
        r
        for r in caplog.records
        if r.name == "frog_bt.rosbridge.client"
        and r.levelno == logging.WARNING
        and "authentication failed" in r.getMessage()
    ]


# ------------------------------------------------------------------ safe YAML

PWN = '!!python/object/apply:os.system ["touch {marker}"]'


def test_python_tags_in_definition_files_are_refused(tmp_path: Path) -> None:
    marker = tmp_path / "pwned"
    tag = PWN.format(marker=marker)
    tree = tmp_path / "tree.yaml"
    tree.write_text(f"root: {tag}\n", encoding="utf-8")
    with pytest.raises(TreeError, match=r"tree\.yaml:1:7: not valid YAML.*python/object"):
        load_tree(tree, load_site())
    site = tmp_path / "site.yaml"
    site.write_text(f"pois: {tag}\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"site\.yaml:\d+:\d+: not valid YAML"):
        load_site(site)
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(f"speed: {tag}\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"scenario\.yaml:\d+:\d+: not valid YAML"):
        load_scenario(scenario)
    assert not marker.exists()


@pytest.mark.parametrize(
    "type_",
    [
        "os.system",
        "py_trees.behaviours.Success",
        "frog_bt.behaviours.navigation.Navigate",
        "__import__",
    ],
)
def test_tree_files_name_only_registered_leaf_types(tmp_path: Path, type_: str) -> None:
    tree = tmp_path / "tree.yaml"
    tree.write_text(f"root: {{type: {type_}}}\n", encoding="utf-8")
    with pytest.raises(TreeError, match="unknown type"):
        load_tree(tree, load_site())
