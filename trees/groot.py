"""The TreeNodesModel palette of a behavior catalog, so Groot2 offers every behavior with its ports.

``tree_nodes_model(catalog)`` returns a BehaviorTree.CPP v4 XML document holding only a
``<TreeNodesModel>``: one ``<Action>`` per catalog behavior with an ``<input_port>`` per
argument (allowed values and description in the port's text), and the engine's own leaves
(Condition, QueryBelief, AskBehavior, AddBelief, RemoveBelief).
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from aeroexec.engine.catalog import BehaviorCatalog

#: The engine's leaves that are not catalog behaviors: (kind, ID, [(direction, port, description)]).
ENGINE_LEAVES = [
    ("Condition", "Condition", [("input", "belief", "a belief expression; SUCCESS when it holds")]),
    ("Action", "QueryBelief", [("input", "belief", "a belief expression; its variables go to the blackboard")]),
    ("Action", "AskBehavior", [("input", "behavior", "a deliberative behavior of the catalog"),
                               ("output", "result", "the blackboard key that receives its result")]),
    ("Action", "AddBelief", [("input", "belief", "a ground belief to add")]),
    ("Action", "RemoveBelief", [("input", "belief", "a belief pattern; matching beliefs are removed")]),
]


def tree_nodes_model(catalog: BehaviorCatalog) -> str:
    """The palette as XML text (UTF-8, indented)."""
    root = ElementTree.Element("root", BTCPP_format="4")
    model = ElementTree.SubElement(root, "TreeNodesModel")
    for behavior in catalog:
        action = ElementTree.SubElement(model, "Action", ID=behavior.name)
        if behavior.description:
            action.set("description", behavior.description)
        for argument in behavior.arguments.values():
            port = ElementTree.SubElement(action, "input_port", name=argument.name)
            notes = [argument.describe()]
            if argument.required:
                notes.append("required")
            if argument.default is not None:
                port.set("default", str(argument.default))
            if argument.description:
                notes.append(argument.description)
            port.text = "; ".join(notes)
    for kind, identifier, ports in ENGINE_LEAVES:
        leaf = ElementTree.SubElement(model, kind, ID=identifier)
        for direction, name, text in ports:
            ElementTree.SubElement(leaf, f"{direction}_port", name=name).text = text
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="unicode", xml_declaration=False) + "\n"
