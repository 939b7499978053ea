"""``frog-bt``: one entry point, one module per sub-command.

Each sub-command module exposes ``add_arguments(parser)`` and ``run(args) -> int``
and is imported only when chosen, so ``frog-bt render`` never loads websockets
or rerun.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import sys

COMMANDS = {
    "run": ("frog_bt.commands.run", "run the executive against a robot (or the simulator)"),
    "sim": ("frog_bt.sim.command", "start the built-in robot and front-end simulator"),
    "demo": ("frog_bt.commands.demo", "simulator and executive together for one full tour"),
    "render": ("frog_bt.commands.render", "draw a tour tree"),
    "check": ("frog_bt.commands.check", "check a tour tree and the site config; draw nothing"),
    "leaves": ("frog_bt.commands.leaves", "list every node type: parameters, keys, docs"),
    "verify": ("frog_bt.commands.verify", "prove a tour tree: every run, every property"),
    "coverage": (
        "frog_bt.commands.coverage",
        "which nodes recorded tours ran, with which outcomes",
    ),
    "schema": ("frog_bt.commands.schema", "print the JSON Schema of tree files or the site"),
    "replay": ("frog_bt.commands.replay", "re-run a recorded tour offline"),
    "report": ("frog_bt.commands.report", "what recorded tours tell: rows, totals, plots"),
    "init": ("frog_bt.commands.init", "write an editable copy of the tour and the site config"),
    "ctl": ("frog_bt.commands.ctl", "send an operator command to a running console"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="frog-bt", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (module, help_) in COMMANDS.items():
        mod = importlib.import_module(module)
        p = sub.add_parser(
            name,
            help=help_,
            description=mod.__doc__,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        mod.add_arguments(p)
        p.set_defaults(_module=mod)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    # Import only the chosen command: build a parser with just that one when we can.
    name = next((a for a in argv if not a.startswith("-")), None)
    if name in COMMANDS:
        # Importing a command allocates much and frees little: no cyclic collections
        # meanwhile (they would only cost time; frog_bt.runtime.memory).
        collecting = gc.isenabled()
        gc.disable()
        try:
            parser = argparse.ArgumentParser(prog="frog-bt")
            sub = parser.add_subparsers(dest="command", required=True)
            mod = importlib.import_module(COMMANDS[name][0])
            p = sub.add_parser(
                name, description=mod.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
            )
            mod.add_arguments(p)
            args = parser.parse_args(argv)
        finally:
            if collecting:
                gc.enable()
        if name != "init":
            from frog_bt.commands import site_folder

            site_folder.apply(args)
        return int(mod.run(args) or 0)
    build_parser().parse_args(argv)  # prints usage or help and exits
    return 2
