"""The Groot2 palette: every catalog behavior with its ports, and the engine's own leaves."""

import defusedxml.ElementTree as ElementTree
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.groot import tree_nodes_model


def test_every_behavior_is_an_action_with_its_arguments_as_ports():
    catalog = default_catalog()
    root = ElementTree.fromstring(tree_nodes_model(catalog))
    assert root.tag == "root" and root.get("BTCPP_format") == "4"
    actions = {a.get("ID"): a for a in root.find("TreeNodesModel").findall("Action")}
    assert set(catalog.behaviors) <= set(actions)
    ports = {p.get("name"): p for p in actions["GO_TO_POINT"].findall("input_port")}
    assert set(ports) == set(catalog.behaviors["GO_TO_POINT"].arguments)
    assert ports["COORDINATES"].text.startswith("[-100, 100] x3")
    assert ports["SPLINE"].get("default") == "no"
    assert actions["TURN_LIGHTS"].find("input_port").text == "{ON, OFF}; required"


def test_the_engine_leaves_are_in_the_palette():
    model = ElementTree.fromstring(tree_nodes_model(default_catalog())).find("TreeNodesModel")
    conditions = {c.get("ID") for c in model.findall("Condition")}
    actions = {a.get("ID") for a in model.findall("Action")}
    assert conditions == {"Condition"}
    assert {"QueryBelief", "AskBehavior", "AddBelief", "RemoveBelief"} <= actions
