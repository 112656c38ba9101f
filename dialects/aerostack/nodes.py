"""Reading the flat ``nodes:`` list of Aerostack's behavior_tree_interpreter into the tree model.

Their missions load unchanged.

The format, as Aerostack's interpreter reads it (``src/controller/source_updated/file_manager.cpp``)::

    nodes:
      - node: 1                         # a whole number, unique
        name: Airplane inspection
        type: control_flow              # control_flow or execution (optional here; must match subtype)
        subtype: sequence
        parent: 0                       # 0 for the root, otherwise the node number of the parent
      - node: 2
        name: Go
        type: execution
        subtype: task
        task: FOLLOW_PATH
        parameters: "path: [[0, 0, 1], [+X, +Y, 1]]"
        wait_for_completion: true
        parent: 1

Children are ordered by node number, as that interpreter orders them. What each subtype becomes:

=====================  ==================================================================
sequence / fallback    Sequence / Fallback (children run to completion, as Aerostack's do)
parallel               Parallel, ``success_count`` = ``threshold``, ``failure_count`` = the
                       children that may fail before success is out of reach
inverter / succeeder   Inverter / ForceSuccess
repeater               Repeat, ``num_cycles`` = ``times``
repeat_until_fail      ForceSuccess over KeepRunningUntilFailure (repeat the child until it
                       fails, then succeed), both named and placed as the node
task                   the behavior named by ``task`` (upper case); ``parameters`` is a YAML
                       mapping in a string whose lower-case argument names become upper-case
                       ports; ``wait_for_completion: false`` adds the port
                       ``_wait_for_completion="false"``
query_belief           QueryBelief with ``parameters`` as its ``belief`` port
add_belief             AddBelief with ``belief`` and, when given, ``multivalued``
remove_belief          RemoveBelief with ``belief``
=====================  ==================================================================

Several parameters are joined with ``&``: ``"path: [[1, 2, 3], [4, 5, 6]] & speed: 2"``.
In parameters a plain ``+X`` is the variable ``?X`` bound by an earlier query_belief node and
becomes the blackboard reference ``{X}``, also inside lists: ``"path: [[+X, +Y, 1]]"`` is the port
``PATH="[[{X}, {Y}, 1]]"``.
"""

from __future__ import annotations

import re

import yaml
from aeroexec.engine.yaml_nodes import MAP, NodeReader, line_of, suggestion
from aeroexec.trees.loaders.common import port_text
from aeroexec.trees.model import TreeDocument, TreeNode

from aeroexec.limits import MAX_NESTING

TREE_ID = "MainTree"
_CONTROL = {"sequence": "Sequence", "fallback": "Fallback", "parallel": "Parallel", "inverter": "Inverter",
            "repeater": "Repeat", "repeat_until_fail": "ForceSuccess", "succeeder": "ForceSuccess"}
_EXECUTION = {"task": "", "query_belief": "QueryBelief", "add_belief": "AddBelief",
              "remove_belief": "RemoveBelief"}
_KEYS = ("node", "name", "type", "subtype", "parent", "task", "parameters", "wait_for_completion",
         "multivalued", "times", "threshold")
#: Keys each subtype may have besides node, name, type, subtype and parent; the first ones listed are required.
_ALLOWED = {"task": ("task", "parameters", "wait_for_completion"), "query_belief": ("parameters",),
            "add_belief": ("parameters", "multivalued"), "remove_belief": ("parameters",),
            "repeater": ("times",), "parallel": ("threshold",)}
_REQUIRED = {"task": ("task",), "query_belief": ("parameters",), "add_belief": ("parameters",),
             "remove_belief": ("parameters",), "repeater": ("times",), "parallel": ("threshold",)}


class _Entry:
    """One item of the ``nodes:`` list, read."""

    def __init__(self, number: int, parent: int, node: TreeNode, item: yaml.Node, parent_node: yaml.Node,
                 subtype: str, threshold: int | None) -> None:
        self.number = number
        self.parent = parent
        self.node = node
        self.item = item
        self.parent_node = parent_node
        self.subtype = subtype
        self.threshold = threshold
        self.children: list[_Entry] = []


def split_parameters(text: str) -> str:
    """Several parameters joined with ``&`` (``"path: [[1,2,3]] & speed: 2"``) as YAML lines, as Aerostack's
    interpreter reads them; an ``&`` inside brackets or quotes is kept."""
    lines, depth, quote, start = [], 0, "", 0
    for index, char in enumerate(text):
        if quote:
            quote = "" if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char in "[{(":
            depth += 1
        elif char in "]})":
            depth -= 1
        elif char == "&" and depth <= 0:
            lines.append(text[start:index].strip())
            start = index + 1
    if not lines:
        return text
    return "\n".join([*lines, text[start:].strip()])


def _parameters(reader: NodeReader, value: yaml.Node, what: str) -> dict[str, str] | None:
    """Aerostack's ``parameters: "path: [[0, 0, 1]] & speed: 2"``: YAML mappings in a string (joined with ``&``),
    as upper-case ports."""
    text = reader.text(value, what)
    if text is None:
        return None
    text = split_parameters(text)
    if not text.strip():
        return {}
    inner = NodeReader(text, reader.file)
    if inner.root is None or inner.failed:
        detail = inner.problems[0].message if inner.problems else "nothing to read"
        reader.error(value, f"{what}: {detail}")
        return None
    if inner.root.tag != MAP:
        reader.error(value, f"{what} must be `argument: value` pairs (like \"angle: 180\"), not {text!r}")
        return None
    ports: dict[str, str] = {}
    for key, (_, item) in (inner.mapping(inner.root, what) or {}).items():
        port = port_text(inner, item, f"{what}: {key}", variables=True)
        if port is not None:
            ports[key.upper()] = port
    for problem in inner.problems:
        if problem.severity == "error":
            reader.error(value, problem.message)
    return ports


def _read_entry(reader: NodeReader, item: yaml.Node, index: int) -> _Entry | None:
    """One item of the list: its place (node, parent, subtype), its keys checked against its subtype, then the node
    it becomes with its ports."""
    place = _read_place(reader, item, f"nodes item {index + 1}")
    if place is None:
        return None
    entries, what, number, parent, subtype = place
    _check_keys(reader, item, entries, what, subtype)
    name = reader.text(entries["name"][1], f"{what}: name") if "name" in entries else None
    node_type = _CONTROL.get(subtype) or _EXECUTION[subtype]
    if subtype == "task" and "task" in entries:
        node_type = (reader.text(entries["task"][1], f"{what}: task") or "").strip().upper()
    ports, threshold = _read_ports(reader, entries, what, subtype)
    node = TreeNode(node_type or "?", name or "", ports, [], reader.file, line_of(item))
    return _Entry(number, parent, node, item, entries["parent"][1], subtype, threshold)


_Entries = dict[str, tuple[yaml.Node, yaml.Node]]


def _read_place(reader: NodeReader, item: yaml.Node, what: str
                ) -> tuple[_Entries, str, int, int, str] | None:
    """An item's keys, its name in messages (``node N``), its node number, its parent's and its subtype (lower
    case, one of the known ones); None when one of them is missing or wrong (each said)."""
    entries = reader.mapping(item, what, known=_KEYS)
    if entries is None:
        return None
    for key in ("node", "subtype", "parent"):
        if key not in entries:
            reader.error(item, f"{what} needs {key}")
    if "node" not in entries or "subtype" not in entries or "parent" not in entries:
        return None
    number = reader.integer(entries["node"][1], f"{what}: node", minimum=1)
    what = f"node {number}" if number is not None else what
    parent = reader.integer(entries["parent"][1], f"{what}: parent", minimum=0)
    raw_subtype = reader.text(entries["subtype"][1], f"{what}: subtype")
    if number is None or parent is None or raw_subtype is None:
        return None
    subtype = raw_subtype.strip().lower()
    if subtype not in _CONTROL and subtype not in _EXECUTION:
        known = [*_CONTROL, *_EXECUTION]
        reader.error(entries["subtype"][1], f"{what}: unknown subtype {raw_subtype}{suggestion(subtype, known)} "
                                            f"(expected one of {', '.join(known)})")
        return None
    return entries, what, number, parent, subtype


def _check_keys(reader: NodeReader, item: yaml.Node, entries: _Entries, what: str, subtype: str) -> None:
    """The item's ``type`` agrees with its subtype, and it has the keys its subtype takes and needs."""
    kind = "control_flow" if subtype in _CONTROL else "execution"
    if "type" in entries:
        declared = (reader.text(entries["type"][1], f"{what}: type") or "").strip().lower()
        if declared and declared != kind:
            reader.error(entries["type"][1], f"{what}: subtype {subtype} is a{'n' if kind[0] == 'e' else ''} "
                                             f"{kind} node, not {declared}")
    allowed = _ALLOWED.get(subtype, ())
    for key, (key_node, _) in entries.items():
        if key not in ("node", "name", "type", "subtype", "parent") and key not in allowed:
            reader.error(key_node, f"{what}: a {subtype} node does not take {key}")
    for key in _REQUIRED.get(subtype, ()):
        if key not in entries:
            reader.error(item, f"{what}: a {subtype} node needs {key}")


def _read_ports(reader: NodeReader, entries: _Entries, what: str, subtype: str) -> tuple[dict[str, str], int | None]:
    """The ports of the node an item becomes, and a parallel node's threshold (placed once its children are known)."""
    if subtype == "task":
        return _task_ports(reader, entries, what), None
    if subtype in _EXECUTION:
        return _belief_ports(reader, entries, what, subtype), None
    ports: dict[str, str] = {}
    if "times" in entries and subtype == "repeater":
        times = reader.integer(entries["times"][1], f"{what}: times", minimum=1)
        if times is not None:
            ports["num_cycles"] = str(times)
    threshold = None
    if "threshold" in entries and subtype == "parallel":
        threshold = reader.integer(entries["threshold"][1], f"{what}: threshold", minimum=1)
    return ports, threshold


def _task_ports(reader: NodeReader, entries: _Entries, what: str) -> dict[str, str]:
    """A task's behavior arguments (``parameters``) and whether the mission waits for it."""
    ports: dict[str, str] = {}
    if "parameters" in entries:
        ports.update(_parameters(reader, entries["parameters"][1], f"{what}: parameters") or {})
    if "wait_for_completion" in entries:
        wait = reader.flag(entries["wait_for_completion"][1], f"{what}: wait_for_completion")
        if wait is False:
            ports["_wait_for_completion"] = "false"
    return ports


def _belief_ports(reader: NodeReader, entries: _Entries, what: str, subtype: str) -> dict[str, str]:
    """A belief node's expression (``parameters``) and, for add_belief, ``multivalued``."""
    ports: dict[str, str] = {}
    if "parameters" in entries:
        belief = reader.text(entries["parameters"][1], f"{what}: parameters")
        if belief is not None and not belief.strip():
            reader.error(entries["parameters"][1], f"{what}: parameters must be a belief expression")
        ports["belief"] = (belief or "").strip()
    if "multivalued" in entries and subtype == "add_belief":
        multivalued = reader.flag(entries["multivalued"][1], f"{what}: multivalued")
        if multivalued is not None:
            ports["multivalued"] = "true" if multivalued else "false"
    return ports


def _assemble(reader: NodeReader, entries: list[_Entry], nodes_key: yaml.Node, complete: bool) -> TreeNode | None:
    by_number: dict[int, _Entry] = {}
    for entry in entries:
        if entry.number in by_number:
            first = line_of(by_number[entry.number].item)
            reader.error(entry.item, f"node {entry.number} is given twice (first at line {first})")
            continue
        by_number[entry.number] = entry
    roots = [e for e in by_number.values() if e.parent == 0]
    for entry in sorted(by_number.values(), key=lambda e: e.number):
        if entry.parent == 0:
            continue
        parent = by_number.get(entry.parent)
        if parent is None:
            reader.error(entry.parent_node, f"node {entry.number}: its parent {entry.parent} is not in the list"
                                            f"{suggestion(str(entry.parent), [str(n) for n in by_number])}")
        elif parent.subtype in _EXECUTION:
            reader.error(entry.parent_node, f"node {entry.number}: its parent {entry.parent} is a {parent.subtype} "
                                            "node; only control_flow nodes have children")
        else:
            parent.children.append(entry)
    if not roots:
        if complete:  # an item that could not be read may be the root
            reader.error(nodes_key, "no node has parent 0: the root of the tree is missing")
        return None
    if len(roots) > 1:
        numbers = ", ".join(str(e.number) for e in roots)
        reader.error(roots[1].item, f"nodes {numbers} all have parent 0: a tree has one root")
        return None
    reached: set[int] = set()
    too_deep: list[_Entry] = []

    def build(entry: _Entry, depth: int = 1) -> TreeNode:
        reached.add(entry.number)
        node = entry.node
        if depth >= MAX_NESTING and entry.children:  # the parents chain deeper than the readers' limit
            too_deep.append(entry)
            return node
        node.children = [build(child, depth + 1) for child in entry.children]
        if entry.subtype == "parallel" and entry.threshold is not None:
            count = len(node.children)
            if entry.threshold > count:
                reader.error(entry.item, f"node {entry.number}: parallel threshold {entry.threshold} is more than "
                                         f"its {count} children")
            node.ports["success_count"] = str(entry.threshold)
            node.ports["failure_count"] = str(max(1, count - entry.threshold + 1))
        if entry.subtype == "repeat_until_fail":
            loop = TreeNode("KeepRunningUntilFailure", node.name, {}, node.children, node.file, node.line)
            node.children = [loop]
        return node

    root = build(roots[0])
    if too_deep:
        reader.error(too_deep[0].item, f"node {too_deep[0].number}: the tree is nested more than {MAX_NESTING} "
                                       "levels deep (the limit of the readers)")
        return None
    for entry in by_number.values():
        if entry.number not in reached and entry.parent in by_number:
            reader.error(entry.item, f"node {entry.number} is not under the root: its parents form a cycle")
    return root


def _other_dialect(items: list[yaml.Node]) -> str | None:
    """One line when no item of a ``nodes:`` list has the keys of Aerostack's format (another project's YAML)."""
    keys: dict[str, None] = {}
    for item in items:
        if isinstance(item, yaml.MappingNode):
            keys.update({str(k.value): None for k, _ in item.value if isinstance(k, yaml.ScalarNode)})
    if not items or keys.keys() & {"node", "subtype", "parent"}:
        return None
    seen = f"its items have {', '.join(list(keys)[:6])}" if keys else "its items are not mappings"
    return (f"this nodes: list is not in the format of Aerostack's behavior_tree_interpreter ({seen}; each node "
            f"needs node, subtype and parent)")


def is_aerostack_nodes(text: str) -> bool:
    """Aerostack's behavior tree interpreter YAML: a top-level ``nodes:`` list."""
    return re.search(r"^nodes\s*:", text, re.MULTILINE) is not None


def read_flat(reader: NodeReader, root: yaml.Node, leaves: list[TreeNode] | None = None) -> TreeDocument | None:
    """The mission of a file whose top-level mapping has Aerostack's ``nodes:`` list; ``leaves`` receives the
    execution nodes that could be read (checked against the catalog even when the file has errors)."""
    top = reader.mapping(root, "an Aerostack mission", known=("nodes",))
    if not top or "nodes" not in top:
        return None
    nodes_key, nodes_value = top["nodes"]
    items = reader.sequence(nodes_value, "nodes")
    if items is None:
        return None
    if not items:
        reader.error(nodes_key, "nodes is empty: the mission has no tree")
        return None
    dialect = _other_dialect(items)
    if dialect:
        reader.error(nodes_key, dialect)
        return None
    entries = [entry for index, item in enumerate(items) if (entry := _read_entry(reader, item, index))]
    if leaves is not None:
        leaves.extend(e.node for e in entries if e.subtype in _EXECUTION)
    tree = _assemble(reader, entries, nodes_key, complete=len(entries) == len(items))
    if tree is None or reader.failed:
        return None
    return TreeDocument({TREE_ID: tree}, TREE_ID, reader.file, {TREE_ID: line_of(nodes_key)})
