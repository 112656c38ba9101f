"""The tree of a running mission as BehaviorTree.CPP's ``WriteTreeToXML(tree, true, true)`` prints it (tinyxml2,
4-space indent): the XML a ``.btlog`` starts with and Groot2's publisher answers its tree request (``T``) with.

``<root BTCPP_format="4">``, one ``<BehaviorTree ID=.. _fullpath=..>`` per tree instance in creation order
(``_fullpath``: the SubTree's ``name``, else ``ID::uid``, below its parent's path), every node with ``name`` and
``_uid`` (the nodes' 1-based places in document order, subtrees expanded), its ports and its ``_skipIf``..
attributes, a ``<SubTree>`` with ``ID``, ``_fullpath`` and ``_uid`` and no children, then a ``<TreeNodesModel>``
of our palette's models of the node types in the tree.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import defusedxml.ElementTree as SafeElementTree
from aeroexec.trees.groot.palette import tree_nodes_model
from aeroexec.trees.runtime.builder import model_of
from aeroexec.trees.runtime.kinds import is_subtree
from py_trees.behaviour import Behaviour

PRE_CONDITIONS = ("_failureIf", "_successIf", "_skipIf", "_while")  # BehaviorTree.CPP's order in the XML
POST_CONDITIONS = ("_onHalted", "_onFailure", "_onSuccess", "_post")
#: BehaviorTree.CPP's built-in ports with defaults: they are in a node's XML even when not written.
BUILT_IN_DEFAULTS = {"Parallel": (("failure_count", "1"), ("success_count", "-1"))}  # in its manifest's order


@dataclass
class _Element:
    tag: str
    attributes: list[tuple[str, str]] = field(default_factory=list)
    children: list[_Element] = field(default_factory=list)
    text: str | None = None


def _attribute(text: str) -> str:
    return (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")
            .replace("'", "&apos;"))


def _print(element: _Element, depth: int, out: list[str]) -> None:
    pad = "    " * depth
    attributes = "".join(f' {name}="{_attribute(value)}"' for name, value in element.attributes)
    if element.text is not None:
        text = element.text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
        out.append(f"{pad}<{element.tag}{attributes}>{text}</{element.tag}>\n")
    elif not element.children:
        out.append(f"{pad}<{element.tag}{attributes}/>\n")
    else:
        out.append(f"{pad}<{element.tag}{attributes}>\n")
        for child in element.children:
            _print(child, depth + 1, out)
        out.append(f"{pad}</{element.tag}>\n")


def _is_port(name: str) -> bool:
    """BehaviorTree.CPP's ``IsAllowedPortName``: a letter first, and not a reserved attribute."""
    return bool(name) and name[0].isalpha() and name not in ("name", "ID")


def _port_attributes(kind: str, ports: dict[str, str], defaults: dict[str, str]) -> list[tuple[str, str]]:
    inserted = [(k, v) for k, v in ports.items() if _is_port(k)]  # then the defaults of the ports not written
    inserted += [(k, v) for k, v in (*BUILT_IN_DEFAULTS.get(kind, ()), *defaults.items()) if k not in ports]
    found = inserted[::-1]  # a small unordered_map lists the last inserted first
    return found + [(k, ports[k]) for k in (*PRE_CONDITIONS, *POST_CONDITIONS) if k in ports]


def _palette_defaults(catalog: Any) -> dict[str, dict[str, str]]:
    if catalog is None:
        return {}
    return {behavior.name: {a.name: str(a.default) for a in behavior.arguments.values() if a.default is not None}
            for behavior in catalog}


def tree_xml(mission: Any, catalog: Any = None) -> str:
    """The XML header of ``mission`` (a TreeMission) as BehaviorTree.CPP's ``WriteTreeToXML(tree, true, true)``."""
    uids = {id(node): uid for uid, (_, node) in enumerate(mission.nodes, 1)}
    defaults = _palette_defaults(catalog)
    root = _Element("root", [("BTCPP_format", "4")])
    root.children.append(_Element("BehaviorTree", [("ID", mission.document.main), ("_fullpath", "")]))
    used: set[str] = set()

    def add(node: Behaviour, parent: _Element, path: str) -> None:
        if id(node) not in uids:  # hidden (a node wrapped by its preconditions): its children show instead
            for child in node.children:
                add(child, parent, path)
            return
        uid, model = uids[id(node)], model_of(node)
        kind = getattr(model, "type", type(node).__name__)
        ports = dict(getattr(model, "ports", {}))
        used.add(kind)
        if is_subtree(kind):
            tree_id = ports.get("ID", "")
            named = getattr(model, "named", True) and node.name not in ("", kind)
            instance = node.name if named else tree_id
            suffix = f"::{uid}" if instance == tree_id else ""
            inner_path = (f"{path}/" if path else "") + (node.name if named else f"{tree_id}::{uid}")
            parent.children.append(_Element(kind, [("ID", tree_id), ("_fullpath", f"{path}/" * bool(path) +
                                                                     instance + suffix), ("_uid", str(uid)),
                                                   *_port_attributes(kind, ports, {})]))
            inner = _Element("BehaviorTree", [("ID", tree_id), ("_fullpath", inner_path)])
            root.children.append(inner)
            for child in node.children:
                add(child, inner, inner_path)
            return
        element = _Element(kind, [("name", node.name), ("_uid", str(uid)),
                                  *_port_attributes(kind, ports, defaults.get(kind, {}))])
        parent.children.append(element)
        for child in node.children:
            add(child, element, path)

    add(mission.root, root.children[0], "")
    root.children.append(_tree_nodes_model(catalog, used))
    out: list[str] = []
    _print(root, 0, out)
    return "".join(out)


def _tree_nodes_model(catalog: Any, used: set[str]) -> _Element:
    models = _Element("TreeNodesModel")
    if catalog is None:
        return models
    palette = SafeElementTree.fromstring(tree_nodes_model(catalog))
    for model in sorted(palette.iter(), key=lambda m: m.get("ID") or ""):
        if model.get("ID") not in used:
            continue
        element = _Element(model.tag, [("ID", model.get("ID", ""))])
        for port in model:
            attributes = [(k, port.get(k, "")) for k in ("name", "type", "default") if k in port.attrib]
            element.children.append(_Element(port.tag, attributes, text=port.text or None))
        models.children.append(element)
    return models
