"""What the mission-file loaders share: the type of ``<Action ID="X">``-style nodes, and YAML values as port text.

Ports are text as an XML attribute would hold it. A YAML value becomes port text this way:

* a scalar stays as written (``1.50`` is ``"1.50"``, ``ON`` is ``"ON"``); an empty value is ``""``;
* a flat list is its items joined by ``", "``: ``[1, 2, 1.5]`` is ``"1, 2, 1.5"``; a list of lists keeps
  all its brackets, so a path of one point stays a path: ``[[0, 0, 1], [1, 0, 1]]`` is
  ``"[[0, 0, 1], [1, 0, 1]]"``; an item holding a comma, bracket, brace, colon or quote is
  single-quoted (a ``{key}`` reference is not);
* ``{P}`` (which YAML reads as a mapping of ``P`` to nothing) is the blackboard reference ``"{P}"``.
"""

from __future__ import annotations

import re

from aeroexec.engine.yaml_nodes import MAP, SEQ, NodeReader
from aeroexec.trees.runtime.manifests import ACTION, CONDITION, CONTROL, DECORATOR

from aeroexec.lazy import lazy_module

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    import yaml
else:  # PyYAML is imported when a text is read, not with this module (a catalog or world kept parsed reads none)
    yaml = lazy_module("yaml")

#: Node tags that name their type in an ``ID`` attribute, as BehaviorTree.CPP writes them.
EXPLICIT_TAGS = (ACTION, CONDITION, CONTROL, DECORATOR)  # BT.CPP's node types, as tags with an ID

_QUOTE_IN_LIST = re.compile(r"[,\[\]{}:#'\"]")
_VARIABLE = re.compile(r"\+([A-Za-z_]\w*)")
_REFERENCE = re.compile(r"\{[^{}\s]+\}")


def resolve_type(tag: str, ports: dict[str, str]) -> tuple[str, str | None]:
    """The node type of ``<tag ...ports>``; ``ports`` loses its ``ID`` when the ID names the type.

    ``<Action ID="GO_TO_POINT"/>`` is a ``GO_TO_POINT`` node and ``<Condition ID="X"/>`` an ``X`` node;
    ``<Condition belief="..."/>`` stays a ``Condition``. The second value is an error message or None.
    """
    if tag not in EXPLICIT_TAGS:
        return tag, None
    node_id = ports.pop("ID", "").strip()
    if node_id:
        return node_id, None
    if tag == CONDITION:
        if "belief" in ports:
            return tag, None
        return tag, "a Condition needs belief=\"...\" (a belief expression) or ID=\"...\" (a registered condition)"
    article = "an" if tag[0] in "AEIOU" else "a"
    return tag, f"{article} {tag} needs ID=\"...\", the type of node it is"


def _reference(node: yaml.Node) -> str | None:
    """``{P}`` written unquoted in YAML: a one-entry mapping of a name to nothing."""
    if node.tag != MAP or len(node.value) != 1:
        return None
    key, value = node.value[0]
    if isinstance(key, yaml.ScalarNode) and NodeReader.is_null(value) and str(key.value).strip():
        return "{" + str(key.value) + "}"
    return None


def _scalar(node: yaml.ScalarNode, variables: bool) -> str:
    if NodeReader.is_null(node):
        return ""
    text = str(node.value)
    if variables and node.style is None:
        match = _VARIABLE.fullmatch(text.strip())
        if match:
            return "{" + match.group(1) + "}"
    return text


def port_text(reader: NodeReader, node: yaml.Node, what: str, variables: bool = False) -> str | None:
    """A YAML value as port text (see the module docstring); None, with an error recorded, when it has none.

    With ``variables`` a plain ``+X`` (Aerostack's reference to a variable bound by a belief query)
    becomes the blackboard reference ``{X}``.
    """
    if isinstance(node, yaml.ScalarNode):
        return _scalar(node, variables)
    reference = _reference(node)
    if reference is not None:
        return reference
    if node.tag == SEQ:
        items = []
        for item in node.value:
            if isinstance(item, yaml.ScalarNode):
                text = _scalar(item, variables)
                if (_QUOTE_IN_LIST.search(text) and not _REFERENCE.fullmatch(text)) or (
                        not text and not reader.is_null(item)):
                    text = "'" + text.replace("'", "''") + "'"
                items.append(text)
                continue
            text = port_text(reader, item, what, variables)
            if text is None:
                return None
            items.append(f"[{text}]" if item.tag == SEQ and not text.startswith("[") else text)
        nested = any(item.tag == SEQ for item in node.value)
        return f"[{', '.join(items)}]" if nested else ", ".join(items)
    reader.error(node, f"{what}: a mapping cannot be a port value (write text, a number, a list or {{key}})")
    return None


def errors_of(reader: NodeReader) -> list[tuple[str, int, str]]:
    """The reader's errors as :class:`~aeroexec.trees.model.TreeFormatError` problems."""
    return [(p.file, p.line, p.message) for p in reader.problems if p.severity == "error"]
