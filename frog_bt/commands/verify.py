"""Prove a tour tree: explore every run of the code that runs, under every answer of the world.

The tree is built by the loader, as `frog-bt run` builds it, and its own nodes are
ticked in a core: the composites, the decorators, the operator's commands, the guards
and each leaf's own `update()` run as in production. Only the world is abstracted:
what no leaf can know in advance (the robot's answer to a goal, the docking state, the
front end's events, a visitor, battery and faults, the operator's commands, a wait
running out) is chosen at every tick from the finite set each node type declares on its
class, and every state the tree can reach is visited, breadth first, from a fresh start
and from every checkpoint the tree writes (a restarted executive resumes from it). The
built-in properties (ends-well, home-obeyed, service-off-obeyed, pause-obeyed,
no-content-while-driving, bounded-retries, no-dead-reads) and the tree file's own
`properties:` are checked, and for each, how often its trigger was reached (states
paused, out of service, ...). Exit 0 when all hold; 1 with the shortest run that breaks
each one that does not, when one holds vacuously (no run reaches its trigger), or when
a node keeps state its class does not declare or its code raised; 2 when the tree or
the configuration is invalid, a leaf type declares no world interface, or a property
of the tree file names a node the tree does not have. `--conformance` replays
recordings on the same tree and checks that every step they took (which nodes run,
tick by tick) is one the exploration has; the first step outside, per recording, is
named with its tick and node, and the exit is 1.

Examples:

  frog-bt verify                                 the packaged tour and site
  frog-bt verify trees/tour.yaml --format mermaid
  frog-bt verify --coverage recordings/          and the share a season reached
  frog-bt verify --conformance recordings/       every recorded step one it explores
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from frog_bt.commands.options import add_tree_argument, load_tree_argument
from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.errors import DefinitionError, TreeErrors, UsageError
from frog_bt.verify.explore import Graph, TooBig
from frog_bt.verify.prove import Verdict, prove
from frog_bt.verify.report import broken_text, summary


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_tree_argument(p)
    p.add_argument(
        "--format",
        choices=("mermaid", "dot"),
        help="draw the tree with the nodes of each broken run marked",
    )
    p.add_argument(
        "--real",
        action="store_true",
        help="accepted and ignored: the real tree is what verify always explores",
    )
    p.add_argument(
        "--conformance",
        type=Path,
        nargs="+",
        metavar="FILE_OR_DIR",
        help="recordings: replay each on the tree and check every step is one it explores",
    )
    p.add_argument(
        "--coverage",
        type=Path,
        metavar="DIR",
        help="recordings: the share of the explored states and transitions they reached",
    )


def run(args: argparse.Namespace) -> int:
    try:
        _, site, tree = load_tree_argument(args)
        verdict = prove(tree, site)
    except UsageError as exc:
        print(f"frog-bt: {exc}", file=sys.stderr)
        return 2
    except TreeErrors as exc:
        for error in exc.errors:
            print(error, file=sys.stderr)
        return 2
    except DefinitionError as exc:
        print(exc, file=sys.stderr)
        return 2
    except TooBig as exc:
        print(f"frog-bt: the tree is too big to verify whole: {exc}", file=sys.stderr)
        return 2
    if args.coverage is not None:
        print(season_share(verdict.graph, args.coverage, site, tree))
    conforms = True
    if args.conformance:
        conforms = conformance_lines(verdict, args.conformance, site, tree)
    if verdict.ok:
        print(summary(verdict))
        return 0 if conforms else 1
    print(broken_text(verdict, args.format))
    return 1


def conformance_lines(verdict: Verdict, paths: list[Path], site: Site, tree: LoadedTree) -> bool:
    """Replay the recordings under ``paths`` on ``tree`` (freshly built for each) and
    print each that took a step the exploration does not allow, then one summary line;
    whether every recording conformed."""
    from frog_bt.offline.conformance import conformance
    from frog_bt.offline.corpus import recordings

    def fresh() -> LoadedTree:
        reload = getattr(tree.factory, "load", None)
        if reload is not None:
            return reload(tree.file, site)  # type: ignore[no-any-return]
        from frog_bt.behaviours import load_tree

        return load_tree(tree.file, site)

    def unreadable(path: Path, why: str) -> None:
        print(f"frog-bt: {path}: {why}", file=sys.stderr)

    files, outside = conformance(
        verdict.graph, verdict.model, site, fresh, recordings(paths), unreadable
    )
    for step in outside:
        print(step.line())
    print(
        f"conformance: {files - len(outside)} of {files} recordings took only steps the "
        "explorer allows"
        + (
            f"; {len(outside)} left the exploration (the world's abstraction missed them)"
            if outside
            else ""
        )
    )
    return not outside and files > 0


def season_share(graph: Graph, directory: Path, site: Site, tree: LoadedTree) -> str:
    """Replay every recording under ``directory`` on ``tree`` and say which share of the
    explored states and transitions it reached, each seen as which nodes run (a
    recording keeps no memory positions or abstract keys)."""
    from frog_bt.behaviours import load_tree
    from frog_bt.offline.corpus import recordings
    from frog_bt.offline.replay import Replay
    from frog_bt.recordings.commands import ReplayError
    from frog_bt.verify.coverage import Reached, explored_configurations

    configs, moves = explored_configurations(graph)
    reached = Reached()
    files = 0
    for path in recordings([directory]):
        try:
            replay = Replay(path, site, load_tree(tree.file, site))
        except (ReplayError, OSError) as exc:
            print(f"frog-bt: {path}: {exc}", file=sys.stderr)
            continue
        replay.observers.attach(replay, [reached])
        replay.run()
        files += 1
    got = len(configs & reached.configs)
    moved = len(moves & reached.moves)
    outside = len(reached.configs - configs)
    return (
        f"coverage: {files} recordings reached {got} of {len(configs)} explored states "
        f"({100 * got / max(1, len(configs)):.0f} %) and {moved} of {len(moves)} transitions "
        f"({100 * moved / max(1, len(moves)):.0f} %), states seen as which nodes run"
        + (f"; {outside} states outside the exploration" if outside else "")
    )
