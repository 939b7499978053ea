"""Prove a loaded tree: explore it, check every built-in property and the designer's,
and count how often each property's trigger was reached (never: vacuous)."""

from __future__ import annotations

from dataclasses import dataclass, field

from frog_bt.config import Site, load_site
from frog_bt.engine.loaded import LoadedTree
from frog_bt.errors import TreeErrors
from frog_bt.verify import designer
from frog_bt.verify.explore import MAX_STATES, Graph
from frog_bt.verify.model import Model, compile_tree
from frog_bt.verify.properties import (
    BUILT_IN,
    Broken,
    Safety,
    Trigger,
    builtin_triggers,
    check_builtin,
)
from frog_bt.verify.real import explore


@dataclass(slots=True)
class Verdict:
    model: Model
    graph: Graph
    checked: list[str]  # every property checked, by name or title
    broken: list[Broken] = field(default_factory=list)
    triggers: dict[str, Trigger] = field(default_factory=dict)  # by name or title
    nodes: dict[str, int] = field(default_factory=dict)  # a designer property: its node
    undeclared: dict[str, set[str]] = field(default_factory=dict)  # class -> fields
    failed: list[str] = field(default_factory=list)  # a node's code raised

    @property
    def vacuous(self) -> list[str]:
        """The properties checked whose trigger no explored run reached."""
        return [name for name in self.checked if self.triggers[name].vacuous]

    @property
    def held(self) -> int:
        """Properties that hold, and not vacuously."""
        return len(set(self.checked) - {b.name for b in self.broken} - set(self.vacuous))

    @property
    def ok(self) -> bool:
        return not self.broken and not self.vacuous and not self.undeclared and not self.failed


def prove(
    tree: LoadedTree,
    site: Site | None = None,
    properties: list[designer.Property] | None = None,
    only: tuple[str, ...] = (),
    limit: int = MAX_STATES,
    restarts: bool = True,
) -> Verdict:
    """Explore ``tree`` (:mod:`.real`: its own nodes ticked, only the world abstracted)
    from a fresh start and, with ``restarts``, from every checkpoint it writes; check the
    built-in properties (``only`` those, if given) and ``properties`` (default: the tree
    file's own). Raises TreeErrors, before exploring, for a leaf type with no declared
    world interface and a property naming a node the tree does not have; TooBig past
    ``limit`` states."""
    model = compile_tree(tree)
    if properties is None:
        properties = designer.read_properties(tree.file) if tree.file.endswith("yaml") else []
    errors = [*model.undeclared_errors(), *designer.check_names(tree.file, properties, model)]
    if errors:
        raise TreeErrors(errors)
    safety = Safety(model)
    graph, found = explore(model, site or load_site(None), safety, limit, restarts)
    broken_builtin = check_builtin(graph, model, safety)
    names = [n for n in BUILT_IN if not only or n in only]
    verdict = Verdict(model, graph, [*names, *(p.title() for p in properties)])
    verdict.undeclared, verdict.failed = found.undeclared, found.failed
    triggers = builtin_triggers(graph, model)
    for name in names:
        verdict.broken += broken_builtin[name]
        verdict.triggers[name] = triggers[name]
    for prop in properties:
        run = designer.check(prop, graph, model)
        if run is not None:
            verdict.broken.append(Broken(prop.title(), "the tree file's own property", run))
        verdict.triggers[prop.title()] = designer.trigger(prop, graph, model)
        verdict.nodes[prop.title()] = min(n.index for n in model.named(prop.names()[0]))
    return verdict
