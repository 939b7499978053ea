"""Prove a loaded tree: explore it, check every built-in property and the designer's."""

from __future__ import annotations

from dataclasses import dataclass, field

from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.verify import designer
from frog_bt.verify.explore import MAX_STATES, Graph, explore
from frog_bt.verify.model import Model, compile_tree
from frog_bt.verify.properties import BUILT_IN, Broken, Safety, check_builtin


@dataclass(slots=True)
class Verdict:
    model: Model
    graph: Graph
    checked: list[str]  # every property checked, by name or title
    broken: list[Broken] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.broken


def prove(
    tree: LoadedTree,
    site: Site | None = None,
    properties: list[designer.Property] | None = None,
    only: tuple[str, ...] = (),
    limit: int = MAX_STATES,
) -> Verdict:
    """Explore ``tree`` and check the built-in properties (``only`` those, if given) and
    ``properties`` (default: the tree file's own). Raises TooBig past ``limit`` states."""
    model = compile_tree(tree, site)
    safety = Safety(model)
    graph = explore(model, safety, limit)
    if properties is None:
        properties = designer.read_properties(tree.file) if tree.file.endswith("yaml") else []
    broken_builtin = check_builtin(graph, model, safety)
    names = [n for n in BUILT_IN if not only or n in only]
    verdict = Verdict(model, graph, [*names, *(p.title() for p in properties)])
    for name in names:
        verdict.broken += broken_builtin[name]
    for prop in properties:
        run = designer.check(prop, graph, model)
        if run is not None:
            verdict.broken.append(Broken(prop.title(), "the tree file's own property", run))
    return verdict
