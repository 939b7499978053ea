"""Each run option from the command line, else the environment, else the site config's
run: section, else its default."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from frog_bt.commands import run as run_command
from frog_bt.commands.settings import fill
from frog_bt.config import RunCfg, load_site
from frog_bt.errors import UsageError


def parse(*argv: str) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    run_command.add_arguments(p)
    return p.parse_args(argv)


def test_the_command_line_wins_then_the_environment_then_the_site() -> None:
    site = RunCfg(
        rosbridge="ws://site:9090",
        frontend="10.0.0.1:5005",
        quiet=True,
        record="/srv/frog/recordings",
        log_format="json",
    )
    env = {
        "FROG_BT_ROSBRIDGE": "ws://env:9090",
        "FROG_BT_SIM_TIME": "yes",
        "FROG_BT_LISTEN": "127.0.0.1:6000",
    }
    args = parse("--rosbridge", "ws://cli:9090")
    sources = fill(args, site, env)
    assert args.rosbridge == "ws://cli:9090"  # given: the command line's
    assert (args.listen, args.sim_time) == ("127.0.0.1:6000", True)  # the environment's
    assert (args.frontend, args.quiet, args.log_format) == ("10.0.0.1:5005", True, "json")
    assert args.record == Path("/srv/frog/recordings")
    assert (args.once, args.fresh, args.watch, args.console) == (False, False, False, None)
    assert sources == {
        "listen": "env",
        "sim_time": "env",
        "frontend": "site",
        "record": "site",
        "quiet": "site",
        "log_format": "site",
    }


def test_a_bad_flag_in_the_environment_names_the_variable() -> None:
    with pytest.raises(UsageError, match="FROG_BT_ONCE maybe: expected 1/true/yes/on"):
        fill(parse(), RunCfg(), {"FROG_BT_ONCE": "maybe"})


def test_a_stop_is_named_in_the_sites_language() -> None:
    """config/site.yaml: language es, each stop with its Spanish name; `name` (the
    CONTRACT's POI table) otherwise, and the code when neither is given."""
    site = load_site()
    assert site.language == "es"
    assert (site.name("POI2"), site.name("POI2b"), site.name("SHOP")) == (
        "Patio de la Montería",
        "Patio de la Montería",
        "Tienda",
    )
    english = site.model_copy(update={"language": "en"})
    assert (english.name("POI2"), english.name("SHOP")) == ("Hunting Courtyard", "Shop")
    assert site.name("NOWHERE") == "NOWHERE"


def test_a_battery_resume_below_battery_low_is_refused_at_its_line(tmp_path: Path) -> None:
    from frog_bt.errors import ConfigError

    text = Path("config/site.yaml").read_text("utf-8")
    lines = text.splitlines()
    at = next(i for i, line in enumerate(lines) if line.strip().startswith("battery_resume:"))
    lines[at] = "  battery_resume: 10"
    site = tmp_path / "site.yaml"
    site.write_text("\n".join(lines) + "\n", "utf-8")
    with pytest.raises(ConfigError) as info:
        load_site(site)
    assert str(info.value) == (
        f"{site}:{at + 1}:19: safety.battery_resume: expected at least battery_low (20): "
        "a tour would start with a battery it aborts at"
    )
