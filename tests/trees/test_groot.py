"""The Groot2 palette: every catalog behavior with its ports, and the engine's own leaves."""

import defusedxml.ElementTree as ElementTree
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.groot.palette import tree_nodes_model


def test_every_behavior_is_an_action_with_its_arguments_as_ports():
    catalog = default_catalog()
    root = ElementTree.fromstring(tree_nodes_model(catalog))
    assert root.tag == "root" and root.get("BTCPP_format") == "4"
    actions = {a.get("ID"): a for a in root.find("TreeNodesModel").findall("Action")}
    assert set(catalog.behaviors) <= set(actions)
    ports = {p.get("name"): p for p in actions["GO_TO_POINT"].findall("input_port")}
    assert set(ports) == {*catalog.behaviors["GO_TO_POINT"].arguments, "timeout"}
    assert ports["COORDINATES"].get("type") == "BT::AnyTypeAllowed" and ports["timeout"].get("type") == "double"
    assert ports["COORDINATES"].text.startswith("POINT in the world")
    assert ports["SPLINE"].get("default") == "no"
    assert actions["TURN_LIGHTS"].find("input_port").text == "{ON, OFF}; required"


def test_the_engine_leaves_are_in_the_palette():
    model = ElementTree.fromstring(tree_nodes_model(default_catalog())).find("TreeNodesModel")
    conditions = {c.get("ID") for c in model.findall("Condition")}
    actions = {a.get("ID") for a in model.findall("Action")}
    assert conditions == {"CheckBelief"}  # <Condition> alone is a reserved tag in BehaviorTree.CPP
    assert {"QueryBelief", "AskBehavior", "AddBelief", "RemoveBelief"} <= actions


def test_every_port_aeroexec_accepts_on_its_leaves_is_declared():
    from aeroexec.engine.catalog.descriptors import DELIBERATIVE
    from aeroexec.trees.groot.palette import palette_ports

    catalog = default_catalog()
    ports = palette_ports(catalog)
    assert ports["AddBelief"] == {"belief", "multivalued"}
    assert all("timeout" in ports[b.name] for b in catalog)
    asked = {a for b in catalog if b.category == DELIBERATIVE for a in b.arguments}
    assert asked and asked | {"behavior", "result", "timeout"} <= ports["AskBehavior"]
