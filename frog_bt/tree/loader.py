"""Build a py_trees tree from YAML files, checking everything before anything connects.

A tree file has a ``root`` node (and an optional ``description``). A node is a
mapping with a ``type``:

* composites ``Sequence`` / ``Selector`` (``memory`` is required: it changes
  behaviour, so it is always explicit) and ``Parallel`` (``policy: all | one``),
  with ``children`` (:mod:`frog_bt.tree.composites`; ``scope:`` makes one start a
  scope);
* decorators (:mod:`frog_bt.tree.decorators`: ``Retry``, ``Timeout``,
  ``FaceStream``), with ``child``;
* leaves (a :class:`~frog_bt.tree.factory.NodeFactory`'s: the tour's are
  :mod:`frog_bt.behaviours`'), their parameters given inline.

Any node may have a ``name``, and ``when: VAR`` / ``when: not VAR`` to keep it
only where a variable is true: a composite or a leaf is then left out with all
it holds; a decorator (a scope, a retry, a checkpoint) is left out alone, and its
child runs as it is. Two constructs are expanded at load time:
``{include: FILE, with: {VAR: VALUE}}`` inserts another file's root, and
``{foreach: stops, include: FILE}`` (in a ``children`` list) inserts FILE once
per tour stop of the site configuration, with that stop's variables.

Strings may use ``{VAR}``; a string that is exactly ``"{VAR}"`` takes the
variable's value and type. Variables: ``dock``, ``recruit_at``,
``nav_attempts``, ``dock_attempts`` from the site, and per stop ``index`` (from 0), ``poi``,
``content``, ``face_stream``, ``projector``, ``check_follower``,
``content_timeout``.

Every error is a :class:`~frog_bt.errors.TreeError` naming the file, the path
inside it and what was expected; blackboard keys read by a leaf that nothing
writes are errors too.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import py_trees
from pydantic import BaseModel

from frog_bt import resources
from frog_bt.config import Site
from frog_bt.engine.loaded import LoadedTree as LoadedTree  # re-exported: what load gives
from frog_bt.engine.loaded import Path_, Where
from frog_bt.engine.observed import Observed
from frog_bt.errors import TreeError, TreeErrors, format_path
from frog_bt.model.key import Scope
from frog_bt.model.keys import by_name
from frog_bt.tree.flow import Gap, gaps
from frog_bt.yamlfile import load_yaml_marked, validate
from frog_bt.yamlmarks import Marks, line_of

if TYPE_CHECKING:
    from frog_bt.tree.registry import NodeRegistry

DEFAULT_TREE_DIR = resources.tree_dir()
DEFAULT_TREE = DEFAULT_TREE_DIR / resources.TREE_FILE
STRUCTURE = {"type", "name", "when"}
_VAR = re.compile(r"\{(\w+)\}")

Behaviour = py_trees.behaviour.Behaviour


def site_variables(site: Site | None) -> dict[str, Any]:
    if site is None:
        return {"dock": "SHOP", "recruit_at": "POI0", "nav_attempts": 3, "dock_attempts": 3}
    return {
        "dock": site.tour.dock,
        "recruit_at": site.tour.recruit_at,
        "nav_attempts": site.navigation.attempts,
        "dock_attempts": site.docking.attempts,
    }


class _Builder:
    def __init__(self, site: Site | None, factory: NodeRegistry) -> None:
        self.site = site
        self.factory = factory
        self.where: dict[int, Where] = {}
        self.scopes: dict[int, Scope] = {}  # id(node) -> the scope it starts
        self.errors: list[TreeError] = []  # found so far; the build goes on past each
        self.documents: dict[str, Any] | None = None  # name -> document (imported XML)
        self.stack: list[Path] = []
        self.marks: dict[str, Marks] = {}  # file -> where each path in it is written

    # ------------------------------------------------------------ files

    def read(self, path: Path) -> Any:
        """A tree document: the YAML file, or (a tree imported from BT.CPP XML) the
        document of that name."""
        if self.documents is not None:
            if path.name not in self.documents:
                raise TreeError(str(path), (), "no such BehaviorTree in the XML file")
            return self.documents[path.name]
        data, self.marks[str(path)] = load_yaml_marked(path, TreeError)
        return data

    def file(self, path: Path, variables: dict[str, Any]) -> tuple[Behaviour | None, str]:
        if path.resolve() in (p.resolve() for p in self.stack):
            raise TreeError(str(path), (), "includes itself (directly or through others)")
        data = self.read(path)
        if not isinstance(data, dict):
            raise TreeError(str(path), (), "expected a mapping with a 'root' node")
        unknown = set(data) - {"root", "description", "properties"}
        if unknown:
            raise TreeError(
                str(path),
                (sorted(unknown)[0],),
                "unknown key (a tree file has 'root', 'description' and 'properties')",
            )
        if "root" not in data:
            raise TreeError(str(path), ("root",), "missing required key")
        self.stack.append(path)
        try:
            nodes = self.node(data["root"], str(path), ("root",), variables)
        finally:
            self.stack.pop()
        if len(nodes) > 1:
            raise TreeError(str(path), ("root",), "expected one node, got a foreach")
        return (nodes[0] if nodes else None), str(data.get("description", ""))

    # ------------------------------------------------------------ nodes

    def _collect(
        self, data: Any, file: str, path: Path_, variables: dict[str, Any]
    ) -> list[Behaviour]:
        """:meth:`node`, with its errors noted and the build going on (all in one pass)."""
        try:
            return self.node(data, file, path, variables)
        except TreeError as exc:
            self.note(exc)
            return []

    def note(self, exc: TreeError) -> None:
        for error in exc.errors if isinstance(exc, TreeErrors) else [exc]:
            if str(error) not in (str(e) for e in self.errors):  # an include, once per stop
                self.errors.append(error)

    def node(self, data: Any, file: str, path: Path_, variables: dict[str, Any]) -> list[Behaviour]:
        """The behaviours for one node entry (none when ``when`` is false, several for foreach)."""
        if not isinstance(data, dict):
            raise TreeError(file, path, f"expected a node (a mapping), got {_short(data)}")
        if "when" in data and not self._when(data["when"], file, (*path, "when"), variables):
            if data.get("type") in self.factory.decorators and "child" in data:
                # a decorator is its own effect: without it, its child runs as it is
                return self._collect(data["child"], file, (*path, "child"), variables)
            return []
        if "foreach" in data:
            return self._foreach(data, file, path, variables)
        if "include" in data:
            return self._include(data, file, path, variables)
        if "type" not in data:
            raise TreeError(file, path, "missing required key 'type' (or 'include', 'foreach')")
        type_ = data["type"]
        if not isinstance(type_, str):
            raise TreeError(file, (*path, "type"), f"expected a type name, got {_short(type_)}")
        name = self._subst(data.get("name", ""), file, (*path, "name"), variables)
        factory = self.factory
        behaviour: Behaviour | None
        if type_ in factory.composites:
            behaviour = self._composite(type_, data, file, path, variables, name)
        elif type_ in factory.decorators:
            behaviour = self._decorator(type_, data, file, path, variables, name)
        elif type_ in factory.leaves:
            behaviour = self._leaf(type_, data, file, path, variables, name)
        else:
            known = factory.names()
            close = difflib.get_close_matches(type_, known, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f" (known: {', '.join(known)})"
            raise TreeError(file, (*path, "type"), f"unknown type {type_!r}{hint}")
        if behaviour is not None:
            self.where[id(behaviour)] = Where(
                file, path, line_of(file, path, self.marks.get(file, {}))
            )
            return [behaviour]
        return []

    def _composite(
        self,
        type_: str,
        data: dict[str, Any],
        file: str,
        path: Path_,
        variables: dict[str, Any],
        name: str,
    ) -> Behaviour:
        cls = self.factory.composites[type_]
        raw = {k: v for k, v in data.items() if k not in STRUCTURE | {"children"}}
        if "memory" in cls.Params.model_fields:
            if "memory" not in raw:
                raise TreeError(
                    file,
                    (*path, "memory"),
                    f"missing required key: a {type_} must say memory: true or false",
                )
            if not isinstance(raw["memory"], bool):
                raise TreeError(
                    file, (*path, "memory"), f"expected true or false, got {_short(raw['memory'])}"
                )
        params = self._params(cls.Params, raw, file, path, variables)
        children_data = data.get("children")
        if not isinstance(children_data, list) or not children_data:
            raise TreeError(file, (*path, "children"), "expected a non-empty list of nodes")
        # (after `when`, a composite may keep no children: it then succeeds at once)
        children: list[Behaviour] = []
        for i, child in enumerate(children_data):
            children += self._collect(child, file, (*path, "children", i), variables)
        node = cls.build(name or type_, params, children)
        if node.scope is not None:
            self.scopes[id(node)] = node.scope
        return node

    def _decorator(
        self,
        type_: str,
        data: dict[str, Any],
        file: str,
        path: Path_,
        variables: dict[str, Any],
        name: str,
    ) -> Behaviour | None:
        cls = self.factory.decorators[type_]
        raw = {k: v for k, v in data.items() if k not in STRUCTURE | {"child"}}
        params = self._params(cls.Params, raw, file, path, variables)
        if "child" not in data:
            raise TreeError(file, (*path, "child"), f"missing required key: a {type_} has a child")
        child = self._collect(data["child"], file, (*path, "child"), variables)
        if len(child) != 1:
            if not child:
                return None  # its child was left out by `when`
            raise TreeError(file, (*path, "child"), "expected one node, got a foreach")
        return cls(name or f"{type_}{_summary(params)}", child[0], params)

    def _leaf(
        self,
        type_: str,
        data: dict[str, Any],
        file: str,
        path: Path_,
        variables: dict[str, Any],
        name: str,
    ) -> Behaviour:
        cls = self.factory.leaves[type_]
        raw = {k: v for k, v in data.items() if k not in STRUCTURE}
        params = self._params(cls.Params, raw, file, path, variables)
        return cls(name or f"{type_}{_summary(params)}", params)

    def _params(
        self,
        model: type[BaseModel],
        raw: dict[str, Any],
        file: str,
        path: Path_,
        variables: dict[str, Any],
    ) -> BaseModel:
        values = {k: self._subst(v, file, (*path, k), variables) for k, v in raw.items()}
        return validate(model, values, file, TreeError, context={"site": self.site}, base=path)

    def _include(
        self, data: dict[str, Any], file: str, path: Path_, variables: dict[str, Any]
    ) -> list[Behaviour]:
        self._no_unknown(data, {"include", "with", "when", "foreach"}, file, path, "include")
        target = data["include"]
        if not isinstance(target, str):
            raise TreeError(file, (*path, "include"), "expected a file name")
        extra = data.get("with", {})
        if not isinstance(extra, dict):
            raise TreeError(file, (*path, "with"), "expected a mapping of variables")
        scope = dict(variables)
        for k, v in extra.items():
            scope[str(k)] = self._subst(v, file, (*path, "with", k), variables)
        included = Path(file).parent / target
        if self.documents is None and not included.is_file():  # said at the line including it
            raise TreeError(file, (*path, "include"), f"no such file: {included}")
        node, _ = self.file(included, scope)
        return [node] if node is not None else []

    def _foreach(
        self, data: dict[str, Any], file: str, path: Path_, variables: dict[str, Any]
    ) -> list[Behaviour]:
        if data["foreach"] != "stops":
            raise TreeError(file, (*path, "foreach"), "expected 'stops' (the site's tour stops)")
        if "include" not in data:
            raise TreeError(file, (*path, "include"), "missing required key: foreach needs include")
        stops = (
            []
            if self.site is None
            else [{**s.model_dump(), "index": i} for i, s in enumerate(self.site.tour.stops)]
        )
        out: list[Behaviour] = []
        for stop in stops:
            nodes = self._include(
                {k: v for k, v in data.items() if k != "foreach"}, file, path, {**variables, **stop}
            )
            for n in nodes:
                assert isinstance(n, Observed), n  # the loader builds only Observed nodes
                n.scope = Scope.STOP
                self.scopes[id(n)] = Scope.STOP
            out += nodes
        return out

    # ------------------------------------------------------------ helpers

    def _when(self, expr: Any, file: str, path: Path_, variables: dict[str, Any]) -> bool:
        if not isinstance(expr, str):
            raise TreeError(file, path, "expected a variable name or 'not NAME'")
        negate = expr.startswith("not ")
        name = expr[4:].strip() if negate else expr.strip()
        if name not in variables:
            raise TreeError(
                file, path, f"unknown variable {name!r} (known: {', '.join(sorted(variables))})"
            )
        return bool(variables[name]) != negate

    def _subst(self, value: Any, file: str, path: Path_, variables: dict[str, Any]) -> Any:
        if isinstance(value, str):
            whole = _VAR.fullmatch(value)
            for match in _VAR.finditer(value):
                if match.group(1) not in variables:
                    raise TreeError(
                        file,
                        path,
                        f"unknown variable {match.group(1)!r} (known: "
                        f"{', '.join(sorted(variables))})",
                    )
            if whole:
                return variables[whole.group(1)]
            return _VAR.sub(lambda m: str(variables[m.group(1)]), value)
        if isinstance(value, list):
            return [self._subst(v, file, (*path, i), variables) for i, v in enumerate(value)]
        if isinstance(value, dict):
            return {k: self._subst(v, file, (*path, k), variables) for k, v in value.items()}
        return value

    @staticmethod
    def _no_unknown(
        data: dict[str, Any], allowed: set[str], file: str, path: Path_, what: str
    ) -> None:
        for key in data:
            if key not in allowed:
                raise TreeError(
                    file,
                    (*path, key),
                    f"unknown key for {what} (expected: {', '.join(sorted(allowed))})",
                )


def _summary(params: BaseModel) -> str:
    values = [
        str(v)
        for v in params.model_dump(exclude_none=True).values()
        if isinstance(v, str | int | float) and not isinstance(v, bool) and v != ""
    ]
    return f" {' '.join(values)}" if values else ""


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def check_keys(tree: LoadedTree) -> None:
    """Every key a node reads or writes is declared (:mod:`frog_bt.model.keys`), and every
    key it reads is written before it on every path (:mod:`.flow`)."""
    errors: list[TreeError] = list(_undeclared(tree))
    for gap in gaps(tree.root):
        error = _gap_error(tree, gap)
        if str(error) not in (str(e) for e in errors):  # one per place, not per stop
            errors.append(error)
    if errors:
        raise_all(errors)


def raise_all(errors: list[TreeError]) -> None:
    """Raise every error at once, sorted by file and line (one: as it is)."""
    errors = sorted(errors, key=lambda e: (e.file, e.line or (0, 0)))
    raise errors[0] if len(errors) == 1 else TreeErrors(errors)


def _undeclared(tree: LoadedTree) -> Iterator[TreeError]:
    declared = by_name()
    for node in tree.nodes():
        where = tree.where.get(id(node), Where(tree.file, ()))
        who = f"{type(node).__name__} {node.name!r}"
        for key in (
            *getattr(node, "reads", ()),
            *getattr(node, "optional_reads", ()),
            *getattr(node, "writes", ()),
        ):
            if declared.get(key.name) is not key:
                yield TreeError(
                    where.file,
                    where.path,
                    f"{who} uses {key.name}, which no key declaration knows "
                    "(frog_bt/model/keys.py, or an input of frog_bt/model/wire.py)",
                )


def _gap_error(tree: LoadedTree, gap: Gap) -> TreeError:
    where = tree.where.get(id(gap.node), Where(tree.file, ()))
    reader = f"{type(gap.node).__name__} {gap.node.name!r}"
    if gap.scope is not None:
        scope = gap.scope.name.lower()
        why = (
            f"a {scope} starts without it: the value from before this {scope} "
            f"is not this {scope}'s; write it in this {scope}, before the reader"
        )
    elif gap.writers:
        at = [_at(tree, w) for w in gap.writers[:3]]
        why = (
            f"{', '.join(at)} write{'s' if len(at) == 1 else ''} it, but not before it on "
            "every path (a later node, another selector alternative, a sibling in "
            "parallel, or a part that may fail or be skipped)"
        )
    else:
        why = "nothing writes it"
    return TreeError(where.file, where.path, f"{reader} reads {gap.key.name}: {why}")


def _at(tree: LoadedTree, node: Behaviour) -> str:
    where = tree.where.get(id(node))
    if where is None:
        return f"{type(node).__name__} {node.name!r}"
    line = where.line
    place = (
        f"{Path(where.file).name}:{line[0]}"
        if line
        else (f"{Path(where.file).name}: {format_path(where.path)}")
    )
    return f"{type(node).__name__} {node.name!r} ({place})"


def load_tree(path: str | Path | None, site: Site | None, factory: NodeRegistry) -> LoadedTree:
    """Load, expand, build and check a tree file (default ``trees/tour.yaml``) whose node
    types are ``factory``'s."""
    path = Path(path) if path is not None else DEFAULT_TREE
    builder = _Builder(site, factory)
    source = path
    if path.suffix.lower() == ".xml":  # BehaviorTree.CPP v4 (Groot2): its trees as documents
        from frog_bt.tree.btcpp import read_xml  # xml.etree: only for such files

        builder.documents, main = read_xml(path)
        path = path.parent / main
    root, description = None, ""
    try:
        root, description = builder.file(path, site_variables(site))
    except TreeError as exc:
        builder.note(exc)
    if builder.errors:  # the structure first: a data-flow check of a broken tree misleads
        raise_all(builder.errors)
    if root is None:
        raise TreeError(str(path), ("root",), "the whole tree was left out by 'when'")
    tree = LoadedTree(root, str(source), description, builder.where, builder.scopes, factory)
    check_keys(tree)
    return tree
