"""Properties of the designer's own, written in the tree file under ``properties:``.

Three templates; each names nodes as the tree does (``name:``, or the type when unnamed;
a name written once in an included file names that node at every stop)::

    properties:
      - {never: [Guide to POI1, Present POI2], together: true}   # never both running
      - {after: Undock, within: 3, reaches: Go to POI0}          # Y starts within N ticks of X
      - {between: [Abort politely, Tour given up], never: Undock} # once A starts, no C before B

``frog-bt check`` checks the names; ``frog-bt verify`` checks the properties.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field

from frog_bt.errors import TreeError
from frog_bt.verify.explore import Graph
from frog_bt.verify.graph import Run, monitor
from frog_bt.verify.model import Model
from frog_bt.verify.properties import Trigger
from frog_bt.yamlfile import load_yaml_marked, validate

Name = Annotated[str, Field(min_length=1)]


class _Property(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Together(_Property):
    """Two nodes never run at once."""

    never: tuple[Name, Name] = Field(description="the two nodes")
    together: bool = Field(True, description="true: never running at the same time")

    def title(self) -> str:
        return f"never {self.never[0]!r} and {self.never[1]!r} together"

    def names(self) -> tuple[str, ...]:
        return self.never


class Reaches(_Property):
    """Once X starts, Y starts within N ticks."""

    after: Name
    within: int = Field(ge=0, description="ticks")
    reaches: Name

    def title(self) -> str:
        return f"after {self.after!r}, within {self.within} ticks, {self.reaches!r}"

    def names(self) -> tuple[str, ...]:
        return (self.after, self.reaches)


class Between(_Property):
    """Once A starts, C does not start before B starts."""

    between: tuple[Name, Name]
    never: Name

    def title(self) -> str:
        return f"between {self.between[0]!r} and {self.between[1]!r}, never {self.never!r}"

    def names(self) -> tuple[str, ...]:
        return (*self.between, self.never)


Property = Together | Reaches | Between


class Properties(BaseModel):
    model_config = ConfigDict(extra="ignore")
    properties: list[Property] = Field(default_factory=list)


def read_properties(path: str | Path) -> list[Property]:
    """The ``properties:`` of a tree file (TreeError with the file and path when wrong)."""
    data, _ = load_yaml_marked(Path(path), TreeError)
    if not isinstance(data, dict) or "properties" not in data:
        return []
    model = validate(Properties, {"properties": data["properties"]}, str(path), TreeError)
    return list(model.properties)


def check_names(path: str | Path, props: list[Property], model: Model) -> list[TreeError]:
    """A TreeError per property naming a node the tree does not have."""
    known = {n.name for n in model.nodes}
    errors = []
    for i, prop in enumerate(props):
        for name in prop.names():
            if name not in known:
                where = ("properties", i)
                errors.append(TreeError(str(path), where, f"no node named {name!r} in the tree"))
    return errors


def check(prop: Property, graph: Graph, model: Model) -> Run | None:
    """The shortest run that breaks ``prop``, or None."""
    if isinstance(prop, Together):
        return _together(prop, graph, model)
    if isinstance(prop, Reaches):
        return _reaches(prop, graph, model)
    return _between(prop, graph, model)


def trigger(prop: Property, graph: Graph, model: Model) -> Trigger:
    """How often ``prop``'s trigger was reached: the states in which the rarer of its two
    nodes runs (together), or the ticks its first node starts (reaches, between)."""
    if isinstance(prop, Together):
        counts = []
        for name in prop.never:
            ids = _ids(model, name)
            counts.append(
                (sum(1 for nodes, _ in graph.states if any(nodes[i] > 0 for i in ids)), name)
            )
        count, name = min(counts)
        return Trigger(count, f"states in which {name!r} runs")
    first = prop.after if isinstance(prop, Reaches) else prop.between[0]
    ids = _ids(model, first)
    starts = sum(1 for _, _, step in graph.each() if _starts(step, ids) is not None)
    return Trigger(starts, f"ticks in which {first!r} starts")


def _ids(model: Model, name: str) -> set[int]:
    return {n.index for n in model.named(name)}


def _together(prop: Together, graph: Graph, model: Model) -> Run | None:
    a, b = _ids(model, prop.never[0]), _ids(model, prop.never[1])
    for s, (nodes, _) in enumerate(graph.states):
        on_a = [i for i in a if nodes[i] > 0]
        on_b = [i for i in b if nodes[i] > 0]
        if on_a and on_b:
            return Run(graph.path(s), note="both running", nodes={*on_a, *on_b})
    return None


def _starts(step: Any, ids: set[int]) -> int | None:
    for pos, (i, started) in enumerate(step.ticked):
        if started and i in ids:
            return pos
    return None


def _reaches(prop: Reaches, graph: Graph, model: Model) -> Run | None:
    x, y = _ids(model, prop.after), _ids(model, prop.reaches)
    memo: dict[tuple[int, int], list[Any] | None] = {}

    def avoid(s: int, left: int) -> list[Any] | None:
        """A run of ``left`` ticks from ``s`` in which no Y starts, or None."""
        if left == 0:
            return []
        if (s, left) in memo:
            return memo[(s, left)]
        memo[(s, left)] = None
        for dst, step in graph.edges[s]:
            if _starts(step, y) is None:
                rest = avoid(dst, left - 1)
                if rest is not None:
                    memo[(s, left)] = [(s, step, dst), *rest]
                    break
        return memo[(s, left)]

    for src, edges in enumerate(graph.edges):
        for dst, step in edges:
            at = _starts(step, x)
            if at is None:
                continue
            later = [i for i, started in step.ticked[at:] if started and i in y]
            if later:
                continue
            rest = avoid(dst, prop.within)
            if rest is not None:
                first = step.ticked[at][0]
                return Run(
                    [*graph.path(src), (src, step, dst), *rest],
                    note=f"{prop.reaches!r} not started within {prop.within} ticks",
                    nodes={first},
                )
    return None


def _between(prop: Between, graph: Graph, model: Model) -> Run | None:
    a, b, c = (_ids(model, prop.between[0]), _ids(model, prop.between[1]), _ids(model, prop.never))

    def bit(step: Any, on: bool) -> tuple[bool, int | None]:
        for i, started in step.ticked:
            if not started:
                continue
            if i in b:
                on = False
            if on and i in c:
                return on, i
            if i in a:
                on = True
        return on, None

    run = monitor(graph, bit)
    if run is not None:
        run.note = f"{prop.never!r} started between {prop.between[0]!r} and {prop.between[1]!r}"
    return run
