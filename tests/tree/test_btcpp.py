"""BehaviorTree.CPP v4 XML (Groot2): export, import back, and what BT.CPP itself accepts."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import behaviortreepy as btcpp
import pytest

from frog_bt.behaviours import FACTORY, load_tree
from frog_bt.commands.render import btcpp_xml
from frog_bt.config import load_site
from frog_bt.tree import render
from frog_bt.tree.catalogue import catalogue

BUILTIN = {
    "Sequence",
    "ReactiveSequence",
    "Fallback",
    "ReactiveFallback",
    "Parallel",
    "RetryUntilSuccessful",
    "ForceSuccess",
    "SubTree",
}


@pytest.fixture(scope="module")
def xml_text() -> str:
    return btcpp_xml(None, load_site())


def test_one_behavior_tree_per_file_subtrees_and_a_model(xml_text: str) -> None:
    root = ET.fromstring(xml_text)
    assert root.get("BTCPP_format") == "4" and root.get("main_tree_to_execute") == "tour"
    assert [t.get("ID") for t in root.findall("BehaviorTree")] == [
        "tour",
        "dock",
        "goto",
        "home",
        "recruit",
        "visit_poi",
    ]
    site = load_site()
    visits = [s for s in root.iter("SubTree") if s.get("ID") == "visit_poi"]
    assert [v.get("poi") for v in visits] == [s.poi for s in site.tour.stops]  # foreach
    assert any(
        {"poi": "{dock}"}.items() <= s.attrib.items()
        for s in root.iter("SubTree")
        if s.get("ID") == "goto"
    )
    # memory composites and py_trees' decorators map to BT.CPP's own nodes
    tags = {e.tag for e in root.iter()}
    assert {
        "Sequence",
        "Fallback",
        "ReactiveFallback",
        "RetryUntilSuccessful",
        "ForceSuccess",
    } <= tags
    assert root.find(".//ReactiveFallback").get("name") == "FROG"
    # every frog-bt node type used is declared, with its parameters as ports
    model = {e.get("ID"): e for e in root.find("TreeNodesModel")}
    params = {n.name: [p.name for p in n.params] for n in catalogue(FACTORY)}
    used = {e.tag for e in root.iter() if e.tag not in BUILTIN} - {
        "root",
        "BehaviorTree",
        "TreeNodesModel",
        "Action",
        "Decorator",
        "input_port",
        "MetadataFields",
        "Metadata",
    }
    assert used == set(model)
    for name, element in model.items():
        assert [p.get("name") for p in element.findall("input_port")] == params[name]
    assert model["FaceStream"].tag == "Decorator" and model["Navigate"].tag == "Action"


def test_import_gives_the_same_tree_and_the_same_xml(xml_text: str, tmp_path: Path) -> None:
    path = tmp_path / "tour.xml"
    path.write_text(xml_text)
    site = load_site()
    imported = load_tree(path, site)
    shipped = load_tree(site=site)
    assert render.text(render.outline(imported.root), keys=True) == render.text(
        render.outline(shipped.root), keys=True
    )
    assert btcpp_xml(path, site) == xml_text  # export, import, export: the same XML


def test_behaviortree_cpp_loads_it_and_creates_the_tree(xml_text: str) -> None:
    """BT.CPP 4 itself (behaviortreepy) accepts the XML. Its simple registration takes no
    ports, so each frog-bt node's attributes are checked against the TreeNodesModel here
    and stripped; built-in nodes keep theirs (num_attempts, SubTree remapping)."""
    root = ET.fromstring(xml_text)
    model = {
        e.get("ID"): (e.tag, {p.get("name") for p in e.findall("input_port")})
        for e in root.find("TreeNodesModel")
    }
    for element in root.iter():
        if element.tag in model:
            extra = set(element.attrib) - model[element.tag][1] - {"name", "_skipIf"}
            assert not extra, (element.tag, extra)
            for key in set(element.attrib) - {"name", "_skipIf"}:
                del element.attrib[key]

    def factory() -> btcpp.BehaviorTreeFactory:
        f = btcpp.BehaviorTreeFactory()
        for name, (kind, _) in model.items():
            if kind == "Action":
                f.register_simple_action(name, lambda node: btcpp.NodeStatus.SUCCESS)
            else:
                f.register_simple_decorator(name, lambda status, node: status)
        return f

    text = ET.tostring(root, encoding="unicode")
    f = factory()
    f.register_behavior_tree_from_text(text)
    assert f.create_tree("tour") is not None
    broken = factory()  # and it does refuse what it does not know
    with pytest.raises(RuntimeError, match="RetryUntilSuccessfull"):
        broken.register_behavior_tree_from_text(
            text.replace("RetryUntilSuccessful", "RetryUntilSuccessfull")
        )
        broken.create_tree("tour")


def test_what_has_no_bt_cpp_equivalent_round_trips(tmp_path: Path) -> None:
    tree = tmp_path / "t.yaml"
    tree.write_text("""root:
  type: Sequence
  memory: false
  children:
    - {type: Timeout, seconds: 30, child: {type: SeekVisitor}}
    - type: Parallel
      policy: one
      synchronise: false
      children:
        - {type: GiveUp, when: not nav_attempts}
        - {type: GiveUp, name: Give up twice}
""")
    site = load_site()
    text = btcpp_xml(tree, site)
    root = ET.fromstring(text)
    sequence = root.find("BehaviorTree/ReactiveSequence")
    assert sequence is not None
    assert sequence.find("ClockTimeout").get("seconds") == "30"  # not BT.CPP's Timeout
    parallel = sequence.find("Parallel")
    assert parallel.attrib == {"success_count": "1", "failure_count": "1", "synchronise": "false"}
    # `when` is kept, as a BT.CPP precondition (the loader leaves the node out)
    assert [(e.get("name"), e.get("_skipIf")) for e in parallel] == [
        (None, "nav_attempts"),
        ("Give up twice", None),
    ]
    xml = tmp_path / "t.xml"
    xml.write_text(text)
    assert btcpp_xml(xml, site) == text
    assert render.text(render.outline(load_tree(xml, site).root)) == render.text(
        render.outline(load_tree(tree, site).root)
    )
