"""A tree document as BehaviorTree.CPP v4 XML (for Groot2 and BehaviorTree.CPP), with the palette of its behaviors.

``write_xml(document, catalog)`` writes every tree of the document in the compact form (``<GO_TO_POINT
COORDINATES="..."/>``, ``<SubTree ID="..."/>``), the main one named by ``main_tree_to_execute``, and a
``<TreeNodesModel>`` with the models of the catalog behaviors it uses (and of the node kinds other packages add),
their ports and defaults, so Groot2 shows them and BehaviorTree.CPP knows their ports.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

import defusedxml.ElementTree as SafeElementTree
from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.trees.groot.palette import tree_nodes_model
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.kinds import added, is_subtree


def _element(node: TreeNode, used: set[str]) -> ElementTree.Element:
    attributes: dict[str, str] = {}
    subtree = is_subtree(node.type)
    if subtree:
        attributes["ID"] = node.ports.get("ID", "")
        if node.named and node.name not in ("", node.type):
            attributes["name"] = node.name
    elif node.name and node.name != node.type:
        attributes["name"] = node.name
    attributes.update({k: v for k, v in node.ports.items() if not (subtree and k == "ID")})
    used.add(node.type)
    element = ElementTree.Element(node.type, attributes)
    for child in node.children:
        element.append(_element(child, used))
    return element


def write_xml(document: TreeDocument, catalog: BehaviorCatalog | None = None) -> str:
    """The document as BehaviorTree.CPP v4 XML text (UTF-8, indented, ending with a newline)."""
    root = ElementTree.Element("root", BTCPP_format="4", main_tree_to_execute=document.main)
    used: set[str] = set()
    for tree_id in [document.main, *(t for t in document.trees if t != document.main)]:
        tree = ElementTree.SubElement(root, "BehaviorTree", ID=tree_id)
        tree.append(_element(document.trees[tree_id], used))
    if catalog is not None:
        models = ElementTree.SubElement(root, "TreeNodesModel")
        modelled = {*catalog.behaviors, *(kind.name for kind in added())}  # BT.CPP knows the rest
        for model in SafeElementTree.fromstring(tree_nodes_model(catalog)).iter():
            if model.get("ID") in used and model.get("ID") in modelled:
                models.append(model)
    ElementTree.indent(root, space="    ")
    return ElementTree.tostring(root, encoding="unicode") + "\n"
