"""What verify says: a summary line, or per broken property one line at the node it
concerns (``file:line:column: path: property: what``, the file the node was written in,
an included one when it was) with its shortest run as numbered ticks on the lines after,
and the tree drawn with the nodes of the run marked (Mermaid or Graphviz dot)."""

from __future__ import annotations

from collections.abc import Iterable

from frog_bt.engine.loaded import Where
from frog_bt.errors import format_path
from frog_bt.verify.explore import Step
from frog_bt.verify.graph import Run
from frog_bt.verify.model import Model
from frog_bt.verify.properties import Broken
from frog_bt.verify.prove import Verdict
from frog_bt.verify.world import By, Event


def summary(verdict: Verdict) -> str:
    """The summary line, then per property how often its trigger was reached."""
    g = verdict.graph
    return "\n".join(
        [
            f"verified: {len(g.states)} states, {g.transitions} transitions, "
            f"{verdict.held} properties hold ({g.seconds:.1f} s)",
            *trigger_lines(verdict),
        ]
    )


def trigger_lines(verdict: Verdict) -> list[str]:
    """``  property: triggered by N what`` per property checked."""
    return [
        f"  {name}: triggered by {t.count} {t.what}"
        for name in verdict.checked
        if (t := verdict.triggers.get(name)) is not None
    ]


def vacuous_finding(verdict: Verdict, name: str) -> str:
    """``file:line:column: path: property: vacuous: ...`` at the node a designer's
    property names first, at the root of the tree file for a built-in one."""
    tree = verdict.model.tree
    index = verdict.nodes.get(name)
    behaviour = tree.root if index is None else verdict.model.nodes[index].behaviour
    at = tree.where.get(id(behaviour)) or tree.where.get(id(tree.root)) or Where(tree.file, ())
    place = f"{at.file}:{at.line[0]}:{at.line[1]}" if at.line else at.file
    trigger = verdict.triggers[name]
    return (
        f"{place}: {format_path(at.path)}: {name}: vacuous: no run reaches its trigger "
        f"(0 {trigger.what}), so it holds without being tested"
    )


def tick_line(model: Model, step: Step) -> str:
    """The inputs and outcomes of one tick that matter: what was chosen (quiet defaults
    left out), what waited, and the events."""
    parts = []
    for c in step.choices:
        if c.by is By.QUIET:
            continue
        if c.node < 0:
            parts.append(f"{c.what}: {c.value}" if c.what != "operator" else f"operator: {c.value}")
        else:
            chooser = model.nodes[c.node]
            what = "" if c.what == "outcome" else f"{c.what} "
            parts.append(f"{chooser.label()} {what}{c.value}")
    for kind, index, _ in step.events:
        if kind is not Event.RETRY:
            parts.append(f"[{kind.value}: {model.nodes[index].label()}]")
        else:
            parts.append(f"[{model.nodes[index].label()} tries again]")
    for index, why in step.waits:
        parts.append(f"{model.nodes[index].label()} {why}")
    return "; ".join(parts) or "nothing new"


def run_lines(model: Model, run: Run) -> list[str]:
    out = []
    for k, (_, step, _) in enumerate(run.ticks, 1):
        mark = (
            "  (the loop starts here)"
            if run.loop_from is not None and k - 1 == run.loop_from
            else ""
        )
        out.append(f"  {k:3d}. {tick_line(model, step)}{mark}")
    if run.loop_from is not None:
        out.append(f"       ... and again from tick {run.loop_from + 1}, for ever")
    if run.note:
        out.append(f"  => {run.note}")
    return out


def where(model: Model, broken: Broken) -> Where:
    """Where the node a broken property concerns was written (the first in the tree when
    it concerns several; the root when none)."""
    tree = model.tree
    first = min(broken.run.nodes, default=None)
    behaviour = tree.root if first is None else model.nodes[first].behaviour
    return tree.where.get(id(behaviour)) or tree.where.get(id(tree.root)) or Where(tree.file, ())


def finding(model: Model, broken: Broken) -> list[str]:
    """``file:line:column: path: property: what``, then the property's meaning and its
    shortest run, indented."""
    at = where(model, broken)
    place = f"{at.file}:{at.line[0]}:{at.line[1]}" if at.line else at.file
    what = broken.run.note or broken.meaning
    return [
        f"{place}: {format_path(at.path)}: {broken.name}: {what}",
        f"  {broken.name}: {broken.meaning}",
        f"  the shortest run ({len(broken.run.ticks)} ticks):",
        *run_lines(model, broken.run),
    ]


def broken_text(verdict: Verdict, fmt: str | None = None) -> str:
    lines = []
    for b in verdict.broken:
        lines += finding(verdict.model, b)
        if fmt:
            lines.append(draw(verdict.model, run_nodes(b.run), b.run.nodes, fmt))
    lines += [vacuous_finding(verdict, name) for name in verdict.vacuous]
    lines += [
        f"{cls}: keeps state its type does not declare: {', '.join(sorted(fields))} "
        "(declare them in its `world`)"
        for cls, fields in sorted(verdict.undeclared.items())
    ]
    lines += [f"{failed}: a node's code raised while verify explored" for failed in verdict.failed]
    g = verdict.graph
    lines.append(
        f"{len({b.name for b in verdict.broken})} properties broken, "
        f"{len(verdict.vacuous)} vacuous, {verdict.held} hold "
        f"({len(g.states)} states, {g.transitions} transitions)"
    )
    lines += trigger_lines(verdict)
    return "\n".join(lines)


def run_nodes(run: Run) -> set[int]:
    return {i for _, step, _ in run.ticks for i, _ in step.ticked}


def draw(model: Model, marked: Iterable[int], strong: Iterable[int], fmt: str) -> str:
    """The tree as Mermaid or dot text: ``marked`` nodes (the run) filled, ``strong`` ones
    (where it broke) outlined red."""
    marked, strong = set(marked), set(strong)
    if fmt == "dot":
        lines = ["digraph tree {", '  node [shape=box, fontname="sans-serif"];']
        for n in model.nodes:
            style = ""
            if n.index in strong:
                style = ', style="filled,bold", fillcolor="#f4cccc", color="#cc0000", penwidth=2'
            elif n.index in marked:
                style = ', style=filled, fillcolor="#d9ead3"'
            label = n.name.replace('"', "'")
            lines.append(f'  n{n.index} [label="{label}"{style}];')
            if n.parent >= 0:
                lines.append(f"  n{n.parent} -> n{n.index};")
        lines.append("}")
        return "\n".join(lines)
    lines = ["flowchart TD"]
    for n in model.nodes:
        label = n.name.replace('"', "'")
        lines.append(f'  n{n.index}["{label}"]')
        if n.parent >= 0:
            lines.append(f"  n{n.parent} --> n{n.index}")
    lines.append("  classDef run fill:#d9ead3")
    lines.append("  classDef broke fill:#f4cccc,stroke:#cc0000,stroke-width:2px")
    run = sorted(marked - strong)
    if run:
        lines.append("  class " + ",".join(f"n{i}" for i in run) + " run")
    if strong:
        lines.append("  class " + ",".join(f"n{i}" for i in sorted(strong)) + " broke")
    return "\n".join(lines)
