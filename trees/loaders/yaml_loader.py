"""Reading behavior-tree missions written in YAML into a TreeDocument, with the line of every node.

Two forms are read. A file whose top-level mapping has the key of a dialect's form is read by that form (the
entry-point group ``aeroexec.yaml_forms``: Aerostack's behavior_tree_interpreter ``nodes:`` list, read by
``aeroexec.dialects.aerostack``). Otherwise it is the nested form, the XML format's tree written as YAML::

    main_tree_to_execute: Mission        # optional when there is one tree
    trees:                               # or `tree: <node>` for a single tree (its ID is MainTree)
      Mission:
        Sequence:
          name: mission                  # optional
          children:
            - TAKE_OFF: {ALTITUDE: 1.5}
            - GO_TO_POINT: {COORDINATES: [1, 2, 1.5]}
            - Condition: "battery_charge_percentage(self, ?X), greater_than(?X, 20)"
            - QueryBelief: "object(?X, marker), code(?X, 3), position(?X, ?P)"
            - GO_TO_POINT: {COORDINATES: {P}}
            - Fallback:                  # a list alone is the children
                - Condition: {belief: "flight_state(self, landed)"}
                - SubTree: {ID: Land, _autoremap: true}
      Land:
        LAND

A node is ``TypeName: body`` (a mapping with one key, the node type) or just ``TypeName`` when it
has no ports. The body is a mapping of ``name``, ``children`` (a list of nodes) or ``child`` (one
node) and the ports; a list, meaning the children; or, for Condition, QueryBelief, AddBelief and
RemoveBelief, the belief expression itself, and for SubTree the ID of the tree. ``Action: {ID: X}``
and ``Condition: {ID: X}`` are read as node X, as in the XML. Port values become text the way the
XML would write them (:mod:`aeroexec.trees.loaders.common`): ``[1, 2, 1.5]`` is ``"1, 2, 1.5"`` and
``{P}``, quoted or not, is the blackboard reference ``"{P}"``.
"""

from __future__ import annotations

import logging
from pathlib import Path

import yaml
from aeroexec.engine.yaml_nodes import MAP, SEQ, NodeReader, line_of, suggestion
from aeroexec.trees.formats import YAML_FORMS, readers
from aeroexec.trees.loaders.common import errors_of, port_text, resolve_type
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode
from aeroexec.trees.runtime.kinds import is_subtree, ports_in

from aeroexec.limits import InputError, read_text

logger = logging.getLogger(__name__)

SINGLE_TREE_ID = "MainTree"
_STR = "tag:yaml.org,2002:str"
_NODE_FORM = ("a tree node is written `TypeName: {ports}` (a mapping with one key, the node type) "
              "or as a bare TypeName")


class _NestedReader:
    """Reads the nested form node by node."""

    def __init__(self, reader: NodeReader) -> None:
        self.reader = reader

    def node(self, node: yaml.Node, what: str) -> TreeNode | None:
        reader = self.reader
        if isinstance(node, yaml.ScalarNode) and node.tag == _STR and str(node.value).strip():
            return self._make(str(node.value), {}, "", [], node)
        if node.tag != MAP or len(node.value) != 1 or not isinstance(node.value[0][0], yaml.ScalarNode):
            reader.error(node, f"{what}: {_NODE_FORM}, not {reader.shown(node)}")
            return None
        key, body = node.value[0]
        node_type = str(key.value).strip()
        if not node_type:
            reader.error(key, f"{what}: the node type is empty")
            return None
        ports: dict[str, str] = {}
        children: list[TreeNode] = []
        name = ""
        if reader.is_null(body):
            pass
        elif body.tag == SEQ:
            children = self.children(body.value, node_type)
        elif isinstance(body, yaml.ScalarNode):
            beliefs = ports_in(node_type, "belief", "query", "new_belief")  # its one port, written alone
            if beliefs:
                ports[beliefs[0]] = str(body.value)
            elif is_subtree(node_type):
                ports["ID"] = str(body.value)
            else:
                reader.error(body, f"{node_type}: give its ports as a mapping (`{node_type}: {{PORT: value}}`), "
                                   f"not the single value {reader.shown(body)}")
        elif body.tag == MAP:
            name, children = self.body(body, node_type, ports)
        return self._make(node_type, ports, name, children, key)

    def body(self, body: yaml.Node, node_type: str, ports: dict[str, str]) -> tuple[str, list[TreeNode]]:
        reader = self.reader
        name = ""
        children: list[TreeNode] = []
        entries = reader.mapping(body, node_type) or {}
        if "children" in entries and "child" in entries:
            reader.error(entries["child"][0], f"{node_type}: give either children or child, not both")
        for key, (_, value) in entries.items():
            if key == "name":
                name = reader.text(value, f"{node_type}: name") or ""
            elif key == "children":
                items = reader.sequence(value, f"{node_type}: children")
                children = self.children(items, node_type) if items is not None else []
            elif key == "child":
                child = self.node(value, f"{node_type}: child")
                children = [child] if child is not None else []
            else:
                text = port_text(reader, value, f"{node_type}: port {key}")
                if text is not None:
                    ports[key] = text
        return name, children

    def children(self, items: list[yaml.Node], parent: str) -> list[TreeNode]:
        found = (self.node(item, f"a child of {parent}") for item in items)
        return [child for child in found if child is not None]

    def _make(self, node_type: str, ports: dict[str, str], name: str, children: list[TreeNode],
              where: yaml.Node) -> TreeNode:
        node_type, problem = resolve_type(node_type, ports)
        if problem:
            self.reader.error(where, problem)
        if is_subtree(node_type):
            if not ports.get("ID", "").strip():
                self.reader.error(where, "a SubTree needs ID, the tree it runs")
            named, name = bool(name), name or ports.get("ID", "")
            return TreeNode(node_type, name, ports, children, self.reader.file, line_of(where), named=named)
        return TreeNode(node_type, name, ports, children, self.reader.file, line_of(where))


def _read_nested(reader: NodeReader, entries: dict[str, tuple[yaml.Node, yaml.Node]]) -> TreeDocument | None:
    nested = _NestedReader(reader)
    trees: dict[str, TreeNode] = {}
    lines: dict[str, int] = {}
    if "tree" in entries and "trees" in entries:
        reader.error(entries["tree"][0], "give either tree (one tree) or trees (trees by ID), not both")
    if "tree" in entries:
        key_node, value = entries["tree"]
        root = nested.node(value, "tree")
        lines[SINGLE_TREE_ID] = line_of(key_node)
        if root is not None:
            trees[SINGLE_TREE_ID] = root
    elif "trees" in entries:
        key_node, value = entries["trees"]
        for tree_id, (id_node, tree_node) in (reader.mapping(value, "trees") or {}).items():
            lines[tree_id] = line_of(id_node)
            if reader.is_null(tree_node):
                reader.error(id_node, f"tree {tree_id} is empty: it needs exactly one node")
                continue
            if tree_node.tag == SEQ:
                reader.error(tree_node, f"tree {tree_id} must be one node, not a list (put them under a Sequence)")
                continue
            root = nested.node(tree_node, f"tree {tree_id}")
            if root is not None:
                trees[tree_id] = root
        if not lines:
            reader.error(key_node, "trees has no tree")
    main = ""
    if "main_tree_to_execute" in entries:
        key_node, value = entries["main_tree_to_execute"]
        main = reader.text(value, "main_tree_to_execute") or ""
        if main and lines and main not in lines:
            reader.error(value, f"main_tree_to_execute names {main}, but there is no such tree"
                                f"{suggestion(main, lines)} (trees: {', '.join(lines)})")
    elif len(lines) > 1:
        reader.error(entries["trees"][0], f"main_tree_to_execute is missing and there are {len(lines)} trees "
                                          f"({', '.join(lines)}): say which one to execute")
    elif lines:
        main = next(iter(lines))
    if reader.failed:
        return None
    return TreeDocument(trees, main, reader.file, lines)


def read_yaml(text: str, file: str = "<yaml>") -> TreeDocument:
    """A mission from YAML text in either form; ``file`` names it in problems."""
    reader = NodeReader(text, file)
    document = None
    leaves: list[TreeNode] = []
    if reader.root is not None:
        document = _read_document(reader, leaves)
    elif not reader.failed:
        reader.error_at(0, "the file is empty: expected tree:, trees: or Aerostack's nodes:")
    if reader.failed or document is None:
        raise TreeFormatError(errors_of(reader) or [(file, 0, "not a behavior-tree mission")], leaves)
    document.warnings += [(p.file, p.line, p.message) for p in reader.problems if p.severity == "warning"]
    logger.debug("read %d behavior trees from %s (main %s)", len(document.trees), file, document.main)
    return document


def _read_document(reader: NodeReader, leaves: list[TreeNode]) -> TreeDocument | None:
    root = reader.root
    assert root is not None
    if root.tag != MAP:
        reader.error(root, f"a YAML mission is a mapping with tree:, trees: or Aerostack's nodes:, "
                           f"not {reader.shown(root)}")
        return None
    keys = [str(k.value) for k, _ in root.value if isinstance(k, yaml.ScalarNode)]
    form = next((readers(YAML_FORMS)[key] for key in keys if key in readers(YAML_FORMS)), None)
    if form is not None:  # a dialect's: Aerostack's nodes:
        return form(reader, root, leaves)
    if "tree" not in keys and "trees" not in keys:
        reader.error(root, "not a behavior-tree mission: expected tree: (one tree), trees: (trees by ID) "
                           "or Aerostack's nodes: list")
        return None
    entries = reader.mapping(root, "the mission", known=("main_tree_to_execute", "trees", "tree", "safety_rules"))
    return _read_nested(reader, entries) if entries is not None else None


def load_yaml(path: str | Path) -> TreeDocument:
    """A mission from a YAML file (nested form or Aerostack's ``nodes:`` list)."""
    try:
        text = read_text(path)
    except InputError as exc:
        raise TreeFormatError([(exc.file, exc.line, exc.message)]) from None
    return read_yaml(text, str(path))
