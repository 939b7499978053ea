"""Draw a built tree as indented text, Graphviz DOT or Mermaid; SVG/PNG through Graphviz.

Pure functions of a py_trees tree (no robot, no network, no clock): :func:`outline`
turns it into :class:`Node` values, numbered ``n0, n1, ...`` in pre-order so
the output is the same on every run; :func:`text`, :func:`dot` and
:func:`mermaid` print them. Only :func:`graphviz` does I/O: it pipes DOT
through the ``dot`` program.

Every node shows its name, its type when the name does not start with it, and
its parameters: a leaf's or decorator's ``describe()``, a Sequence's or
Selector's ``memory``, a Parallel's ``policy`` (and ``synchronise``). With
``keys``, a node with blackboard keys shows ``reads /a /b?  writes /c``, where
``/b?`` is an optional read (a default applies while nothing has written it).

Symbols (text): ascii uses py_trees' (``{-}``/``[-]`` sequence with/without
memory, ``{o}``/``[o]`` selector, ``/_/`` parallel, ``-^-`` decorator, ``-->``
leaf); unicode draws guide lines and ``→`` sequence, ``?`` selector, ``⇉``
parallel, ``◇`` decorator, ``•`` leaf. DOT and Mermaid: sequence box ``→``,
selector octagon (Mermaid: hexagon) ``?``, parallel parallelogram ``⇉``,
decorator ellipse (Mermaid: stadium), leaf rounded box.
"""

from __future__ import annotations

import itertools
import json
import shutil
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import py_trees

from frog_bt.errors import FrogError

Behaviour = py_trees.behaviour.Behaviour

ASCII = {
    "sequence": "[-]",
    "sequence*": "{-}",
    "selector": "[o]",
    "selector*": "{o}",
    "parallel": "/_/",
    "decorator": "-^-",
    "leaf": "-->",
    "composite": "[+]",
}
GLYPH = {
    "sequence": "→",
    "selector": "?",
    "parallel": "⇉",
    "decorator": "◇",
    "leaf": "•",
    "composite": "+",
}
# kind -> (DOT shape, DOT style, Mermaid opening and closing brackets, fill colour)
LOOK = {
    "sequence": ("box", "filled", '["', '"]', "#fde0c5"),
    "selector": ("octagon", "filled", '{{"', '"}}', "#cfe8fc"),
    "parallel": ("parallelogram", "filled", '[/"', '"/]', "#fff3b0"),
    "decorator": ("ellipse", "filled", '(["', '"])', "#e8e8e8"),
    "leaf": ("box", "rounded,filled", '("', '")', "#ffffff"),
    "composite": ("box", "filled", '["', '"]', "#e8e8e8"),
}


class GraphvizError(FrogError):
    """Graphviz's ``dot`` is missing or failed; the message is one line."""


@dataclass(frozen=True, slots=True)
class Node:
    """One behaviour as drawn: what it is, its parameters and blackboard keys, its children."""

    id: str
    kind: str  # sequence, selector, parallel, decorator, leaf (composite: any other)
    type: str
    name: str
    params: tuple[tuple[str, str], ...]
    reads: tuple[str, ...] = ()
    optional_reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    memory: bool = False
    children: tuple[Node, ...] = ()

    def walk(self) -> Iterator[Node]:
        """This node and all below it, in pre-order."""
        yield self
        for child in self.children:
            yield from child.walk()

    @property
    def named_by_type(self) -> bool:
        """The name starts with the type (``Navigate POI1``), so the type need not be shown."""
        return self.name == self.type or self.name.startswith(self.type + " ")

    def label(self) -> str:
        """``name (Type) [k=v, ...]``: the type only when the name does not start with it."""
        out = self.name if self.named_by_type else f"{self.name} ({self.type})"
        if self.params:
            out += " [" + ", ".join(f"{k}={v}" for k, v in self.params) + "]"
        return out

    def detail(self) -> str:
        """Second line of a graph label: the type (unless in the name) and the parameters."""
        parts = [] if self.named_by_type else [self.type]
        if self.params:
            parts.append(", ".join(f"{k}={v}" for k, v in self.params))
        return " ".join(parts)

    def key_groups(self) -> list[str]:
        """``["reads /a /b?", "writes /c"]`` (empty groups left out)."""
        reads = [*self.reads, *(f"{k}?" for k in self.optional_reads)]
        groups = [("reads", reads), ("writes", list(self.writes))]
        return [f"{word} {' '.join(keys)}" for word, keys in groups if keys]


# ------------------------------------------------------------------ outline


def outline(root: Behaviour) -> Node:
    """The tree below ``root`` as :class:`Node` values, ids ``n0, n1, ...`` in pre-order."""
    return _outline(root, itertools.count())


def _outline(behaviour: Behaviour, ids: Iterator[int]) -> Node:
    node_id = f"n{next(ids)}"
    kind, memory, params = _kind(behaviour)
    children = tuple(_outline(child, ids) for child in behaviour.children)
    return Node(
        node_id,
        kind,
        type(behaviour).__name__,
        " ".join(behaviour.name.split()),
        params,
        _key_names(behaviour, "reads"),
        _key_names(behaviour, "optional_reads"),
        _key_names(behaviour, "writes"),
        memory,
        children,
    )


def _key_names(behaviour: Behaviour, group: str) -> tuple[str, ...]:
    return tuple(key.name for key in getattr(behaviour, group, ()))


def _kind(b: Behaviour) -> tuple[str, bool, tuple[tuple[str, str], ...]]:
    if isinstance(b, py_trees.composites.Parallel):
        policy = b.policy
        if isinstance(policy, py_trees.common.ParallelPolicy.SuccessOnAll):
            return (
                "parallel",
                False,
                (("policy", "all"), ("synchronise", _value(policy.synchronise))),
            )
        if isinstance(policy, py_trees.common.ParallelPolicy.SuccessOnOne):
            return "parallel", False, (("policy", "one"),)
        return "parallel", False, (("policy", type(policy).__name__),)
    if isinstance(b, py_trees.composites.Sequence | py_trees.composites.Selector):
        kind = "sequence" if isinstance(b, py_trees.composites.Sequence) else "selector"
        scope = getattr(b, "scope", None)
        return (
            kind,
            b.memory,
            (
                ("memory", _value(b.memory)),
                *((("scope", scope.name.lower()),) if scope is not None else ()),
            ),
        )
    kind = (
        "decorator"
        if isinstance(b, py_trees.decorators.Decorator)
        else "composite"
        if isinstance(b, py_trees.composites.Composite)
        else "leaf"
    )
    describe = getattr(b, "describe", None)
    described: dict[str, Any] = describe() if callable(describe) else {}
    params = tuple((str(k), _value(v)) for k, v in described.items() if v is not None and v != "")
    return kind, False, params


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        plain = value and not any(c.isspace() or c in ',[]=()"' for c in value)
        return value if plain else json.dumps(value, ensure_ascii=False)
    return json.dumps(value, ensure_ascii=False, default=str, separators=(",", ":"))


# ------------------------------------------------------------------ text


def text(root: Node, *, unicode: bool = False, keys: bool = False) -> str:
    """An indented tree, one node per line (ascii: py_trees' symbols; unicode: guide lines)."""
    lines: list[str] = []

    def line(node: Node) -> str:
        groups = node.key_groups() if keys else []
        return "  ".join([node.label(), *groups])

    def ascii_lines(node: Node, depth: int) -> None:
        symbol = ASCII[node.kind + ("*" if node.memory else "")]
        lines.append(f"{'    ' * depth}{symbol} {line(node)}")
        for child in node.children:
            ascii_lines(child, depth + 1)

    def unicode_lines(node: Node, lead: str, branch: str) -> None:
        lines.append(f"{lead}{branch}{GLYPH[node.kind]} {line(node)}")
        below = lead + ("" if not branch else "│   " if branch == "├── " else "    ")
        for i, child in enumerate(node.children):
            unicode_lines(child, below, "└── " if i == len(node.children) - 1 else "├── ")

    if unicode:
        unicode_lines(root, "", "")
    else:
        ascii_lines(root, 0)
    lines.append("")
    lines.append(UNICODE_LEGEND if unicode else ASCII_LEGEND)
    if keys:
        lines.append("keys: reads /key, reads if set /key?, writes /key")
    return "\n".join(lines) + "\n"


ASCII_LEGEND = (
    "legend: {-} sequence with memory, [-] without; {o} selector with memory, "
    "[o] without; /_/ parallel; -^- decorator; --> leaf"
)
UNICODE_LEGEND = "legend: → sequence, ? selector, ⇉ parallel, ◇ decorator, • leaf"


# ------------------------------------------------------------------ graphs


def _graph_lines(node: Node, keys: bool) -> list[str]:
    glyph = "" if node.kind in ("leaf", "decorator") else GLYPH[node.kind] + " "
    return [glyph + node.name, *filter(None, [node.detail()]), *(node.key_groups() if keys else [])]


def _dot_quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def dot(root: Node, *, keys: bool = False, rankdir: str = "LR") -> str:
    """Graphviz DOT for the tree (``rankdir``: ``LR`` left-to-right, the default, or
    ``TB`` top-down)."""
    out = [
        "digraph tree {",
        f"    graph [rankdir={rankdir}, ordering=out, nodesep=0.2, ranksep=0.35, "
        'fontname="Helvetica"];',
        '    node [fontname="Helvetica", fontsize=10, margin="0.12,0.05", color="#555555"];',
        '    edge [color="#555555", arrowsize=0.6];',
    ]
    for node in root.walk():
        shape, style, _, _, fill = LOOK[node.kind]
        label = "\\n".join(_dot_quote(line)[1:-1] for line in _graph_lines(node, keys))
        out.append(
            f'    {node.id} [label="{label}", shape={shape}, style="{style}", fillcolor="{fill}"];'
        )
    out += [f"    {node.id} -> {child.id};" for node in root.walk() for child in node.children]
    out.append("}")
    return "\n".join(out) + "\n"


def _mermaid_escape(text: str) -> str:
    # Mermaid decodes #name; and #number; entities inside quoted labels.
    for char, entity in (
        ("#", "#35;"),
        ("&", "#amp;"),
        ('"', "#quot;"),
        ("<", "#lt;"),
        (">", "#gt;"),
        ("`", "#96;"),
    ):
        text = text.replace(char, entity)
    return text


def mermaid(root: Node, *, keys: bool = False, rankdir: str = "LR") -> str:
    """A Mermaid flowchart of the tree (``LR`` by default, ``TD`` with ``rankdir="TB"``)."""
    out = [f"flowchart {'LR' if rankdir == 'LR' else 'TD'}"]
    for node in root.walk():
        _, _, opening, closing, _ = LOOK[node.kind]
        label = "<br/>".join(_mermaid_escape(line) for line in _graph_lines(node, keys))
        out.append(f"    {node.id}{opening}{label}{closing}:::{node.kind}")
    out += [f"    {node.id} --> {child.id}" for node in root.walk() for child in node.children]
    used = sorted({node.kind for node in root.walk()})
    out += [
        f"    classDef {kind} fill:{LOOK[kind][4]},stroke:#555555,color:#000000" for kind in used
    ]
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------ images


def graphviz(dot_text: str, fmt: str, timeout: float = 60.0) -> bytes:
    """``dot_text`` rendered by Graphviz's ``dot -T<fmt>``; :class:`GraphvizError` if it can't."""
    program = shutil.which("dot")
    if program is None:
        raise GraphvizError(
            f"{fmt} needs Graphviz's `dot` program, which is not installed "
            "(apt-get install graphviz)"
        )
    try:
        result = subprocess.run(
            [program, f"-T{fmt}"],
            input=dot_text.encode("utf-8"),
            capture_output=True,
            timeout=timeout,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise GraphvizError(f"dot -T{fmt}: {exc}") from exc
    if result.returncode != 0:
        why = result.stderr.decode("utf-8", "replace").strip().splitlines()
        raise GraphvizError(f"dot -T{fmt} failed: {why[0] if why else result.returncode}")
    return result.stdout
