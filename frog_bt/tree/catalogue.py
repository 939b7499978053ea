"""The catalogue of every node type a tree file can name: parameters, keys, docstring.

Built from a node factory (:class:`~frog_bt.tree.registry.NodeRegistry`: the tour's is
:data:`frog_bt.behaviours.FACTORY`)
and the key declarations (:mod:`frog_bt.model.keys`), so it cannot drift from the code.
``frog-bt leaves`` prints it as Markdown or JSON; the node reference in ``docs/TREES.md``
is its Markdown (a test compares).
"""

from __future__ import annotations

import inspect
import json
import types
import typing
from dataclasses import asdict, dataclass, field
from typing import Any

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from frog_bt.model.key import Key
from frog_bt.model.keys import by_name
from frog_bt.tree.registry import NodeRegistry


@dataclass(frozen=True, slots=True)
class Param:
    name: str
    type: str
    default: Any  # "required" when it has none
    meaning: str = ""


@dataclass(frozen=True, slots=True)
class NodeType:
    name: str
    kind: str  # composite | decorator | leaf
    params: tuple[Param, ...]
    reads: tuple[str, ...] = ()
    optional_reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    doc: str = ""
    children: str = field(default="")  # "children" | "child" | ""


def _type_name(annotation: Any) -> str:
    if annotation is None or annotation is type(None):
        return "null"
    origin = typing.get_origin(annotation)
    if origin is typing.Literal:
        return " | ".join(str(a) for a in typing.get_args(annotation))
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in typing.get_args(annotation))
    if origin is typing.Annotated:
        return _type_name(typing.get_args(annotation)[0])
    return getattr(annotation, "__name__", str(annotation))


def _params(model: type[BaseModel]) -> tuple[Param, ...]:
    out = []
    for name, info in model.model_fields.items():
        default = "required" if info.is_required() else info.get_default(call_default_factory=True)
        if default is PydanticUndefined:
            default = "required"
        out.append(Param(name, _type_name(info.annotation), default, info.description or ""))
    return tuple(out)


def _names(keys: tuple[Key[Any], ...]) -> tuple[str, ...]:
    return tuple(k.name for k in keys)


def _node(cls: Any, kind: str) -> NodeType:
    children = {"composite": "children", "decorator": "child"}.get(kind, "")
    return NodeType(
        cls.__name__,
        kind,
        _params(cls.Params),
        _names(getattr(cls, "reads", ())),
        _names(getattr(cls, "optional_reads", ())),
        _names(getattr(cls, "writes", ())),
        inspect.cleandoc(cls.__doc__ or ""),
        children,
    )


def catalogue(factory: NodeRegistry) -> list[NodeType]:
    """Every node type of ``factory``, composites first, then decorators and leaves by
    name."""
    return [
        *(_node(factory.composites[n], "composite") for n in factory.composites),
        *(_node(factory.decorators[n], "decorator") for n in sorted(factory.decorators)),
        *(_node(factory.leaves[n], "leaf") for n in sorted(factory.leaves)),
    ]


@dataclass(frozen=True, slots=True)
class KeyInfo:
    name: str
    type: str
    source: str  # input | leaf | executive
    scope: str  # process | tour | visitor | stop
    meaning: str


def key_catalogue() -> list[KeyInfo]:
    """Every key a tree can read or write, by name."""
    return [
        KeyInfo(k.name, k.type_name, k.source.value, k.scope.name.lower(), k.doc)
        for _, k in sorted(by_name().items())
    ]


def as_json(nodes: list[NodeType]) -> str:
    return json.dumps([asdict(n) for n in nodes], indent=2, default=str) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def as_markdown(nodes: list[NodeType]) -> str:
    """One section per node type: its docstring, a parameter table and its keys."""
    out: list[str] = []
    for kind, title in (
        ("composite", "Composites"),
        ("decorator", "Decorators and scopes"),
        ("leaf", "Leaves"),
    ):
        out.append(f"### {title}\n")
        for node in (n for n in nodes if n.kind == kind):
            out.append(f"#### `{node.name}`\n")
            if node.doc:
                out.append(node.doc + "\n")
            if node.params:
                out.append("| parameter | type | default | meaning |")
                out.append("|---|---|---|---|")
                for p in node.params:
                    default = "required" if p.default == "required" else f"`{p.default!r}`"
                    out.append(
                        f"| `{p.name}` | {_cell(p.type)} | {_cell(default)} | {_cell(p.meaning)} |"
                    )
                out.append("")
            keys = []
            if node.children:
                keys.append(f"takes `{node.children}`")
            if node.reads:
                keys.append("reads " + ", ".join(f"`{k}`" for k in node.reads))
            if node.optional_reads:
                keys.append("reads if set " + ", ".join(f"`{k}`" for k in node.optional_reads))
            if node.writes:
                keys.append("writes " + ", ".join(f"`{k}`" for k in node.writes))
            if keys:
                line = "; ".join(keys)
                out.append(line[0].upper() + line[1:] + ".\n")
    out.append("### Keys\n")
    out.append(
        "Every value a tree reads or writes (`frog_bt/model/keys.py`, and the "
        "robot's inputs in `frog_bt/model/wire.py`). A value lives as long as its scope: "
        "starting a scope clears its keys and those of narrower scopes "
        "(tour > visitor > stop).\n"
    )
    out.append("| key | type | written by | scope | meaning |")
    out.append("|---|---|---|---|---|")
    for k in key_catalogue():
        out.append(
            f"| `{k.name}` | {_cell(k.type)} | {k.source} | {k.scope} | {_cell(k.meaning)} |"
        )
    return "\n".join(out).rstrip() + "\n"
