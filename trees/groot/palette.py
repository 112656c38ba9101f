"""The TreeNodesModel palette of a behavior catalog, so Groot2 and BehaviorTree.CPP know every node aeroexec reads.

``tree_nodes_model(catalog)`` returns a BehaviorTree.CPP v4 XML document holding only a ``<TreeNodesModel>``: one
``<Action>`` per catalog behavior with an ``<input_port>`` per argument (its C++ type where one fits, else
``BT::AnyTypeAllowed``; allowed values and description in the port's text) and the ``timeout`` every behavior
leaf takes, and the engine's own leaves: CheckBelief (a condition), QueryBelief, AddBelief (``multivalued``),
RemoveBelief and AskBehavior, whose ports are the arguments of every deliberative behavior besides its own.
Every port aeroexec accepts on these nodes is declared, so a tree aeroexec accepts loads in BehaviorTree.CPP.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.catalog.arguments import ArgumentDescriptor
from aeroexec.engine.catalog.descriptors import DELIBERATIVE
from aeroexec.trees.conversions import ANY, BOOL, DOUBLE, INT, STRING
from aeroexec.trees.runtime.kinds import added, kind_of

ANY_TYPE = "BT::AnyTypeAllowed"
_TYPES = {"NUMBER": "double", "INTEGER": "int", "BOOLEAN": "bool", "TEXT": "std::string", "BELIEF": "std::string"}

#: The engine's leaves that are not catalog behaviors, as the palette lists them (kind and ports: their manifests),
#: then the node kinds other packages add (``trees.runtime.kinds``).
ENGINE_LEAVES = ("CheckBelief", "QueryBelief", "AddBelief", "RemoveBelief", "AddRule", "AskBehavior")
#: C++ types of the runtime's port types.
_CPP_TYPES = {STRING: "std::string", BOOL: "bool", INT: "int", DOUBLE: "double", ANY: ANY_TYPE}


def port_type(argument: ArgumentDescriptor) -> str:
    """The C++ type BehaviorTree.CPP would give the argument's port (AnyTypeAllowed for points, paths, lists)."""
    if argument.choices or argument.dimensions > 1:
        return "std::string" if argument.choices else ANY_TYPE
    return _TYPES.get(argument.value_type or "", ANY_TYPE if argument.value_type else "double")


def _argument_port(parent: ElementTree.Element, argument: ArgumentDescriptor) -> None:
    port = ElementTree.SubElement(parent, "input_port", name=argument.name, type=port_type(argument))
    notes = [argument.describe()]
    if argument.required:
        notes.append("required")
    if argument.default is not None:
        port.set("default", str(argument.default))
    if argument.description:
        notes.append(argument.description)
    port.text = "; ".join(notes)


def tree_nodes_model(catalog: BehaviorCatalog) -> str:
    """The palette as XML text (UTF-8, indented)."""
    root = ElementTree.Element("root", BTCPP_format="4")
    model = ElementTree.SubElement(root, "TreeNodesModel")
    asked: dict[str, ArgumentDescriptor] = {}
    for behavior in catalog:
        action = ElementTree.SubElement(model, "Action", ID=behavior.name)
        if behavior.description:
            action.set("description", behavior.description)
        for argument in behavior.arguments.values():
            _argument_port(action, argument)
            if behavior.category == DELIBERATIVE:
                asked.setdefault(argument.name, argument)
        if "timeout" not in behavior.arguments:
            ElementTree.SubElement(action, "input_port", name="timeout", type="double").text = (
                "seconds before the behavior times out (overrides the catalog's)")
    for kind in [*(kind_of(name) for name in ENGINE_LEAVES), *added()]:
        manifest = kind.manifest  # type: ignore[union-attr]
        leaf = ElementTree.SubElement(model, manifest.kind, ID=kind.name)  # type: ignore[union-attr]
        for port in manifest.ports:
            ElementTree.SubElement(leaf, f"{port.direction}_port", name=port.name,
                                   type=_CPP_TYPES.get(port.type, ANY_TYPE)).text = port.description
        if kind.behavior_port:  # type: ignore[union-attr]
            for argument in asked.values():
                if argument.name not in kind.ports:  # type: ignore[union-attr]
                    _argument_port(leaf, argument)
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="unicode", xml_declaration=False) + "\n"


def palette_ports(catalog: BehaviorCatalog) -> dict[str, set[str]]:
    """Node ID -> the ports the palette declares for it (what BehaviorTree.CPP accepts on that node)."""
    model = ElementTree.fromstring(tree_nodes_model(catalog)).find("TreeNodesModel")
    return {node.get("ID", ""): {port.get("name", "") for port in node} for node in model}  # type: ignore[union-attr]
