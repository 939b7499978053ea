"""JSON Schemas of the files a content designer edits: tree files and the site config.

Generated from the same models the loader validates with (each node type's
``Params``, the catalogue, :class:`~frog_bt.config.Site`), so that an editor
with YAML language support completes node types and parameters and flags
mistakes as you type. The shipped files point at the generated schemas
(``# yaml-language-server: $schema=...``); ``frog-bt schema tree|site`` prints
them. What a schema cannot say (the data-flow check, POI names, variables
defined) is left to ``frog-bt check``.
"""

from __future__ import annotations

import json
from typing import Any

from frog_bt.config import Site
from frog_bt.tree.catalogue import catalogue
from frog_bt.tree.registry import NodeRegistry

TREE_SCHEMA_FILE = "tree.schema.json"
SITE_SCHEMA_FILE = "site.schema.json"
VARIABLE = {
    "type": "string",
    "pattern": r"^\{\w+\}$",
    "description": "a tree variable, e.g. {poi}, taking its value and type",
}
NODE = {"$ref": "#/$defs/node"}
COMMON = {
    "name": {"type": "string", "description": "shown in render, telemetry and logs"},
    "when": {
        "type": "string",
        "pattern": r"^(not )?\w+$",
        "description": "keep this node only where the variable is true (or false)",
    },
}


_NAME = {"type": "string", "minLength": 1, "description": "a node's name in the tree"}
PROPERTY = {
    "description": "a property `frog-bt verify` proves (docs/TREES.md, proving your tree)",
    "anyOf": [
        {
            "title": "never together",
            "type": "object",
            "additionalProperties": False,
            "required": ["never"],
            "properties": {
                "never": {"type": "array", "items": _NAME, "minItems": 2, "maxItems": 2},
                "together": {"type": "boolean"},
            },
        },
        {
            "title": "after, within, reaches",
            "type": "object",
            "additionalProperties": False,
            "required": ["after", "within", "reaches"],
            "properties": {
                "after": _NAME,
                "within": {"type": "integer", "minimum": 0},
                "reaches": _NAME,
            },
        },
        {
            "title": "between, never",
            "type": "object",
            "additionalProperties": False,
            "required": ["between", "never"],
            "properties": {
                "between": {"type": "array", "items": _NAME, "minItems": 2, "maxItems": 2},
                "never": _NAME,
            },
        },
    ],
}


def _params(cls: Any, defs: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
    schema = cls.Params.model_json_schema(ref_template="#/$defs/{model}")
    defs.update(schema.pop("$defs", {}))
    props = {
        name: {
            "anyOf": [prop, VARIABLE],
            **({"description": prop["description"]} if "description" in prop else {}),
        }
        for name, prop in schema.get("properties", {}).items()
    }
    return props, list(schema.get("required", []))


def tree_schema(factory: NodeRegistry) -> dict[str, Any]:
    defs: dict[str, Any] = {}
    kinds: list[dict[str, Any]] = []
    for node in catalogue(factory):
        cls = factory.type_of(node.name)
        props, required = _params(cls, defs)
        if node.kind == "composite":
            props["children"] = {"type": "array", "items": NODE, "minItems": 1}
            required = [*required, "children"]
        elif node.kind == "decorator":
            props["child"] = NODE
            required = [*required, "child"]
        kinds.append(
            {
                "title": node.name,
                "description": node.doc.split("\n\n")[0],
                "type": "object",
                "additionalProperties": False,
                "properties": {"type": {"const": node.name}, **COMMON, **props},
                "required": ["type", *required],
            }
        )
    kinds.append(
        {
            "title": "include",
            "description": "another tree file's root, with variables",
            "type": "object",
            "additionalProperties": False,
            "required": ["include"],
            "properties": {
                "include": {"type": "string"},
                "with": {"type": "object"},
                "when": COMMON["when"],
            },
        }
    )
    kinds.append(
        {
            "title": "foreach",
            "description": "a tree file once per tour stop (in children)",
            "type": "object",
            "additionalProperties": False,
            "required": ["foreach", "include"],
            "properties": {
                "foreach": {"const": "stops"},
                "include": {"type": "string"},
                "with": {"type": "object"},
                "when": COMMON["when"],
            },
        }
    )
    defs["node"] = {"anyOf": kinds}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "frog-bt tree file",
        "type": "object",
        "additionalProperties": False,
        "required": ["root"],
        "properties": {
            "description": {"type": "string"},
            "root": NODE,
            "properties": {"type": "array", "items": PROPERTY},
        },
        "$defs": defs,
    }


def site_schema() -> dict[str, Any]:
    schema = Site.model_json_schema()
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "frog-bt site configuration",
        **schema,
    }


def dumps(schema: dict[str, Any]) -> str:
    return json.dumps(schema, indent=1, sort_keys=True) + "\n"
