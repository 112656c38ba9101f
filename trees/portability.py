"""What of a tree mission BehaviorTree.CPP (and Groot2) would not read as aeroexec does: ``verify --strict-btcpp``.

``portability_problems(document, catalog)`` finds, each with file:line:

* a file that is not BehaviorTree.CPP XML (YAML, TML);
* ``<Condition belief=...>`` (BT.CPP refuses a ``<Condition>`` without ID: ``<CheckBelief>`` is portable);
* ``{key}`` inside a longer value (``"{x}, {y}, 3"``: to BT.CPP one key named ``x}, {y}, 3``; a value is a
  blackboard pointer only when it is all ``{key}``);
* a pre-condition written as a belief expression, and ``belief("...")`` in a script (aeroexec's extensions);
* a port the palette does not declare on a catalog behavior or an engine leaf (a lower-case argument name, an
  alias): BT.CPP refuses ports a node's model does not list;
* what the loader read that BT.CPP 4.10 or Groot2 refuses (``TreeDocument.not_portable``: a raw ``<`` or ``&`` in
  an attribute, names BT.CPP 4.10 does not allow), and a BehaviorTree or SubTree ID that names a registered node.
"""

from __future__ import annotations

from aeroexec.engine.catalog import BehaviorCatalog
from aeroexec.engine.errors import MissionProblem
from aeroexec.trees.groot.palette import palette_ports
from aeroexec.trees.model import COMMON_ATTRIBUTES, POSTCONDITIONS, PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.ports import bare_key, template_keys
from aeroexec.trees.runtime.kinds import kind_of, kinds, ports_in
from aeroexec.trees.runtime.manifests import CONDITION
from aeroexec.trees.script import ScriptError, compile_script

KIND = "NOT_PORTABLE"


def _problem(node: TreeNode | None, document: TreeDocument, message: str) -> MissionProblem:
    file = (node.file if node is not None else "") or document.file
    return MissionProblem("error", message, file, node.line if node is not None else 0, KIND)


def _node_problems(node: TreeNode, palette: dict[str, set[str]]) -> list[str]:
    found: list[str] = []
    if node.tag == CONDITION and node.type == node.tag:  # the node type's word as a tag, as BT.CPP reads it
        found.append("<Condition belief=...> is refused by BehaviorTree.CPP and Groot2 (<Condition> needs an ID): "
                     "write <CheckBelief belief=\"...\"/>")
    scripted = (*ports_in(node.type, "script"), *PRECONDITIONS, *POSTCONDITIONS)
    for port, text in node.ports.items():
        if port in scripted:
            try:
                script = compile_script(text)
            except ScriptError:
                found.append(f"{port}=\"{text}\" is a belief expression, aeroexec's old reading: BehaviorTree.CPP "
                             f"reads a script there (write belief(\"...\") in a script, or a <CheckBelief> node)")
                continue
            if not script.portable:
                found.append(f"{port}=\"{text}\" uses belief(\"...\"), aeroexec's extension of BT.CPP's scripts")
            continue
        keys = template_keys(text)
        if keys and bare_key(text) is None:
            found.append(f"{port}=\"{text}\": {{key}} inside a longer value is aeroexec's extension; to "
                         f"BehaviorTree.CPP it is one key named {text.strip()[1:-1]!r} (build the value with a "
                         f"Script, or write the whole value as one {{key}})")
    declared = palette.get(node.type)
    if declared is not None:
        for port in node.ports:
            if port not in declared and port not in COMMON_ATTRIBUTES:
                found.append(f"the port {port} of {node.type} is not in the palette (aeroexec groot-model): "
                             f"BehaviorTree.CPP refuses it (ports: {', '.join(sorted(declared)) or 'none'})")
    return found


def portability_problems(document: TreeDocument, catalog: BehaviorCatalog) -> list[MissionProblem]:
    """Every construct of ``document`` that BehaviorTree.CPP would refuse or read differently."""
    if not document.file.lower().endswith(".xml") or document.file.lower().endswith(".tml.xml"):
        return [_problem(None, document, "not a BehaviorTree.CPP file: only its v4 XML is portable")]
    palette = palette_ports(catalog)
    problems = [MissionProblem("error", message, file, line, KIND) for file, line, message in document.not_portable]
    registered = {*kinds(), *palette}
    for tree_id in document.trees:
        if tree_id in registered:  # BT.CPP 4.10
            problems.append(MissionProblem("error", "The attribute [ID] of tag <BehaviorTree> must not use the name "
                                                    f"of a registered Node ({tree_id})", document.file,
                                           document.lines.get(tree_id, 0), KIND))
    for root in document.trees.values():
        for node in root.walk():
            problems.extend(_problem(node, document, message) for message in _node_problems(node, palette))
            kind = kind_of(node.type)
            if kind is not None and kind.subtree and node.ports.get("ID", "").strip() in registered:
                problems.append(_problem(node, document, "The attribute [ID] of tag <SubTree> must not use the name "
                                                         f"of a registered Node ({node.ports['ID'].strip()})"))
    return problems
