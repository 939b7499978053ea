"""BehaviorTree.CPP v4 XML (what Groot2 opens and edits), from and to frog-bt trees.

Export (:func:`to_xml`) writes one ``<BehaviorTree>`` per tree file (its ID is the
file's stem): an ``include`` becomes a ``<SubTree>`` whose attributes are the
``with:`` variables (port remapping), a ``foreach`` one ``<SubTree>`` per tour stop
with that stop's variables, and a ``<TreeNodesModel>`` declares every frog-bt
node type used, with its ports (the parameters). Mapping:

=====================================  =====================================
frog-bt                                BehaviorTree.CPP v4
=====================================  =====================================
``Sequence`` memory: true / false      ``Sequence`` / ``ReactiveSequence``
``Selector`` memory: true / false      ``Fallback`` / ``ReactiveFallback``
``Parallel`` policy: all / one         ``Parallel`` success_count -1 / 1
``Retry`` attempts: N / null           ``RetryUntilSuccessful`` num_attempts N / -1
``FailureIsSuccess``                   ``ForceSuccess``
``when: VAR`` / ``when: not VAR``      ``_skipIf="!VAR"`` / ``_skipIf="VAR"``
``Timeout`` (project-clock seconds)    ``ClockTimeout`` (a custom node)
other decorators and leaves            custom nodes of the same name
=====================================  =====================================

Import (:func:`read_xml`) reads such a file back into tree documents for the
loader (``--tree FILE.xml``): export, import and export again gives the same XML.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from frog_bt.config import Site
from frog_bt.errors import TreeError
from frog_bt.tree.catalogue import NodeType, catalogue
from frog_bt.tree.registry import NodeRegistry
from frog_bt.yamlfile import load_yaml

Load = Callable[[str], dict[str, Any]]  # a tree document, by the path that includes it

CONTROLS = {
    ("Sequence", True): "Sequence",
    ("Sequence", False): "ReactiveSequence",
    ("Selector", True): "Fallback",
    ("Selector", False): "ReactiveFallback",
}
FROM_CONTROL = {v: k for k, v in CONTROLS.items()}
RETRY, FORCE = "RetryUntilSuccessful", "ForceSuccess"
# frog-bt types whose name is a different BT.CPP built-in: exported under another name
SCOPE = "_frogScope"  # a composite's scope: no BT.CPP equivalent
RENAMED = {"Timeout": "ClockTimeout"}  # ours counts project-clock seconds, BT.CPP's wall ms
FROM_RENAMED = {v: k for k, v in RENAMED.items()}
_VAR = re.compile(r"^\{\w+\}$")


# ------------------------------------------------------------------ export


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return "null" if value is None else str(value)


def _when(node: ET.Element, when: Any) -> None:
    if when is None:
        return
    text = str(when).strip()
    node.set("_skipIf", text[4:].strip() if text.startswith("not ") else f"!{text}")


class _Exporter:
    def __init__(self, site: Site | None) -> None:
        self.site = site
        self.trees: dict[str, ET.Element] = {}
        self.used: set[str] = set()
        self.stack: list[str] = []

    def document(self, tree_id: str, data: dict[str, Any], load: Load) -> None:
        if tree_id in self.trees or tree_id in self.stack:
            return
        self.stack.append(tree_id)
        element = ET.Element("BehaviorTree", {"ID": tree_id})
        if data.get("description"):
            element.set("_description", " ".join(str(data["description"]).split()))
        self.trees[tree_id] = element
        for child in self.node(data["root"], load):
            element.append(child)
        self.stack.pop()

    def node(self, data: dict[str, Any], load: Load) -> list[ET.Element]:
        if "foreach" in data:
            stops = [] if self.site is None else self.site.tour.stops
            out = []
            for i, stop in enumerate(stops):
                extra = {**stop.model_dump(), "index": i, **data.get("with", {})}
                out += self.node(
                    {
                        "include": data["include"],
                        "with": extra,
                        **({"when": data["when"]} if "when" in data else {}),
                    },
                    load,
                )
            return out
        if "include" in data:
            target = str(data["include"])
            tree_id = Path(target).stem
            self.document(tree_id, load(target), load)
            element = ET.Element("SubTree", {"ID": tree_id})
            for key, value in (data.get("with") or {}).items():
                element.set(str(key), _text(value))
            _when(element, data.get("when"))
            return [element]
        type_ = data["type"]
        params = {
            k: v
            for k, v in data.items()
            if k not in ("type", "name", "when", "child", "children", "memory")
        }
        scope = params.pop("scope", None)
        if type_ in ("Sequence", "Selector"):
            element = ET.Element(CONTROLS[(type_, bool(data["memory"]))])
        elif type_ == "Parallel":
            element = ET.Element(
                "Parallel",
                {
                    "success_count": "1" if params.pop("policy", "all") == "one" else "-1",
                    "failure_count": "1",
                },
            )
            if params.pop("synchronise", True) is False:
                element.set("synchronise", "false")  # no BT.CPP equivalent (docs/TREES.md)
        elif type_ == "Retry":
            attempts = params.pop("attempts", None)
            element = ET.Element(
                RETRY, {"num_attempts": "-1" if attempts is None else _text(attempts)}
            )
        elif type_ == "FailureIsSuccess":
            element = ET.Element(FORCE)
        else:
            element = ET.Element(RENAMED.get(type_, type_))
            self.used.add(type_)
        if "name" in data:
            element.set("name", str(data["name"]))
        if scope is not None:
            element.set(SCOPE, _text(scope))  # BT.CPP ignores "_" attributes it does not know
        for key, value in params.items():
            element.set(str(key), _text(value))
        _when(element, data.get("when"))
        for child in data.get("children") or []:
            element.extend(self.node(child, load))
        if "child" in data:
            element.extend(self.node(data["child"], load))
        return [element]


def _model(types: set[str], factory: NodeRegistry) -> ET.Element:
    model = ET.Element("TreeNodesModel")
    nodes: dict[str, NodeType] = {n.name: n for n in catalogue(factory)}
    for name in sorted(types):
        node = nodes[name]
        kind = "Decorator" if name in factory.decorators else "Action"
        element = ET.SubElement(model, kind, {"ID": RENAMED.get(name, name)})
        for param in node.params:
            port = ET.SubElement(element, "input_port", {"name": param.name})
            if param.default != "required" and param.default is not None:
                port.set("default", _text(param.default))
            port.text = param.meaning or param.type
        if node.doc:
            ET.SubElement(element, "MetadataFields").append(
                ET.Element("Metadata", {"description": node.doc.split("\n\n")[0]})
            )
    return model


def to_xml(
    tree_path: Path,
    site: Site | None,
    factory: NodeRegistry,
    documents: dict[str, dict[str, Any]] | None = None,
) -> str:
    """The tree file at ``tree_path`` (and what it includes) as BT.CPP v4 XML; with
    ``documents`` (an imported XML's), those instead of the files."""

    def load(target: str, base: Path = tree_path.parent) -> dict[str, Any]:
        if documents is not None:
            return documents[Path(target).stem]
        data: dict[str, Any] = load_yaml(base / target, TreeError)  # a tree file (YAML)
        return data

    exporter = _Exporter(site)
    main = tree_path.stem
    exporter.document(main, load(tree_path.name), load)
    root = ET.Element("root", {"BTCPP_format": "4", "main_tree_to_execute": main})
    for tree_id in sorted(exporter.trees, key=lambda t: (t != main, t)):
        root.append(exporter.trees[tree_id])
    root.append(_model(exporter.used, factory))
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


# ------------------------------------------------------------------ import


def _value(text: str) -> Any:
    if _VAR.match(text):
        return text
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    return value if value is None or isinstance(value, str | int | float | bool) else text


def _from_element(element: ET.Element) -> dict[str, Any]:
    attrs = dict(element.attrib)
    data: dict[str, Any] = {}
    skip = attrs.pop("_skipIf", None)
    if element.tag == "SubTree":
        data["include"] = attrs.pop("ID")
        if attrs:
            data["with"] = {k: _value(v) for k, v in attrs.items()}
    else:
        tag = element.tag
        scope = attrs.pop(SCOPE, None)
        if tag in FROM_CONTROL:
            type_, memory = FROM_CONTROL[tag]
            data = {"type": type_, "memory": memory}
        elif tag == "Parallel":
            data = {
                "type": "Parallel",
                "policy": "one" if attrs.pop("success_count", "-1") == "1" else "all",
            }
            attrs.pop("failure_count", None)
            if attrs.pop("synchronise", "true") == "false":
                data["synchronise"] = False
        elif tag == RETRY:
            attempts = _value(attrs.pop("num_attempts", "-1"))
            data = {
                "type": "Retry",
                "attempts": None if isinstance(attempts, int) and attempts < 0 else attempts,
            }
        elif tag == FORCE:
            data = {"type": "FailureIsSuccess"}
        else:
            data = {"type": FROM_RENAMED.get(tag, tag)}
        if "name" in attrs:
            data["name"] = attrs.pop("name")
        if scope is not None:
            data["scope"] = scope
        data.update({k: _value(v) for k, v in attrs.items()})
        children = [_from_element(c) for c in element]
        if tag in FROM_CONTROL or tag == "Parallel":
            data["children"] = children
        elif children:
            data["child"] = children[0]
    if skip is not None:
        data["when"] = skip[1:] if skip.startswith("!") else f"not {skip}"
    return data


def read_xml(path: Path) -> tuple[dict[str, dict[str, Any]], str]:
    """The tree documents of a BT.CPP v4 XML file (by BehaviorTree ID) and the main ID."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise TreeError(str(path), (), f"cannot read BT.CPP XML: {exc}") from None
    if root.get("BTCPP_format") != "4":
        raise TreeError(str(path), (), 'expected <root BTCPP_format="4">')
    documents: dict[str, dict[str, Any]] = {}
    for tree in root.findall("BehaviorTree"):
        children = list(tree)
        if len(children) != 1:
            raise TreeError(str(path), (tree.get("ID", "?"),), "expected one root node")
        doc: dict[str, Any] = {"root": _from_element(children[0])}
        if tree.get("_description"):
            doc["description"] = tree.get("_description")
        documents[tree.get("ID", "")] = doc
    main = root.get("main_tree_to_execute") or next(iter(documents), "")
    if main not in documents:
        raise TreeError(str(path), (), f"no BehaviorTree {main!r} to execute")
    return documents, main


def tree_xml(path: Path, site: Site | None, factory: NodeRegistry) -> str:
    """The tree file at ``path`` as BT.CPP v4 XML: exported from its YAML files, or
    re-exported from an XML file (the same XML)."""
    if path.suffix.lower() == ".xml":
        documents, main = read_xml(path)
        return to_xml(path.parent / f"{main}.yaml", site, factory, documents)
    return to_xml(path, site, factory)
