"""Print the JSON Schema of tree files or of the site configuration.

Generated from the models the loader checks with; the shipped `trees/*.yaml` and
`config/site.yaml` point at copies of them (`# yaml-language-server: $schema=`),
so an editor with YAML support completes and checks as you type.

Examples:

  frog-bt schema tree > trees/tree.schema.json
  frog-bt schema site > config/site.schema.json
"""

from __future__ import annotations

import argparse
import sys

from frog_bt.behaviours import FACTORY
from frog_bt.tree.schema import dumps, site_schema, tree_schema


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("which", choices=("tree", "site"), help="which file's schema")


def run(args: argparse.Namespace) -> int:
    sys.stdout.write(dumps(tree_schema(FACTORY) if args.which == "tree" else site_schema()))
    return 0
