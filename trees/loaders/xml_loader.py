"""Reading behavior-tree missions written in BehaviorTree.CPP's XML format 4 (the one Groot2 edits) into a TreeDocument.

The file is parsed with expat, as ``defusedxml``'s SAX parser parses it (without SAX, whose ``saxutils`` imports
``urllib.request`` and ``ssl`` at every start): a DOCTYPE, entity declarations and external
references are refused before anything is expanded (no billion laughs, no reading other files),
and every element keeps the line it starts on. What is read::

    <root BTCPP_format="4" main_tree_to_execute="Mission">
      <include path="landing.xml"/>              <!-- relative to this file -->
      <BehaviorTree ID="Mission">
        <Sequence name="mission">
          <TAKE_OFF ALTITUDE="1.5"/>
          <Action ID="GO_TO_POINT" COORDINATES="1, 2, 1.5"/>
          <Condition belief="battery_charge_percentage(self, ?X), greater_than(?X, 20)"/>
          <SubTree ID="Land" target="{goal}" _autoremap="true"/>
        </Sequence>
      </BehaviorTree>
      <TreeNodesModel>...</TreeNodesModel>      <!-- ignored -->
    </root>

``BTCPP_format`` must be 4 when given; ``main_tree_to_execute`` may be left out when the file
declares one tree. ``<Action ID="X">``, ``<Condition ID="X">``, ``<Control ID="X">`` and
``<Decorator ID="X">`` are nodes of type ``X``; ``<Condition belief="..."/>`` is a belief condition.
Every other attribute, ``_skipIf``/``_successIf``/``_failureIf``/``_while``/``_onSuccess``... included,
is kept as a port. All problems found are raised together as one :class:`TreeFormatError`.
"""

from __future__ import annotations

import logging
import os
import re
from dataclasses import dataclass, field
from xml.parsers import expat

from aeroexec.engine.yaml_nodes import suggestion
from aeroexec.trees.loaders.btcpp_names import model_name_problem, port_name_problem, refused
from aeroexec.trees.loaders.common import EXPLICIT_TAGS, resolve_type
from aeroexec.trees.loaders.lenient_xml import escape_attributes
from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode
from aeroexec.trees.runtime.kinds import is_subtree
from aeroexec.trees.runtime.manifests import CONDITION, SUBTREE
from defusedxml.common import DefusedXmlException, DTDForbidden, EntitiesForbidden, ExternalReferenceForbidden

from aeroexec.limits import MAX_NESTING, InputError, read_bytes

logger = logging.getLogger(__name__)

_ROOT_CHILDREN = ("BehaviorTree", "include", "TreeNodesModel", "SafetyRules")  # the rules: engine/safety


@dataclass
class _Element:
    tag: str
    attrs: dict[str, str]
    line: int
    children: list[_Element] = field(default_factory=list)


class _Collector:
    """Builds a light element tree whose elements know their lines, from expat's callbacks; refuses a DOCTYPE,
    entity declarations and external references (as ``defusedxml`` does) before anything is expanded."""

    def __init__(self) -> None:
        self.parser = expat.ParserCreate()
        self.stack: list[_Element] = []
        self.root: _Element | None = None
        self.parser.StartElementHandler = self.start_element
        self.parser.EndElementHandler = self.end_element
        self.parser.StartDoctypeDeclHandler = self.doctype
        self.parser.EntityDeclHandler = self.entity
        self.parser.UnparsedEntityDeclHandler = self.unparsed_entity
        self.parser.ExternalEntityRefHandler = self.external_reference

    @property
    def line(self) -> int:
        return self.parser.CurrentLineNumber

    def start_element(self, name: str, attrs: dict[str, str]) -> None:
        if len(self.stack) >= MAX_NESTING:
            raise _TooDeep(f"<{name}> is nested more than {MAX_NESTING} elements deep (the limit of the readers)")
        element = _Element(name, dict(attrs), self.line)
        if self.stack:
            self.stack[-1].children.append(element)
        else:
            self.root = element
        self.stack.append(element)

    def end_element(self, name: str) -> None:
        self.stack.pop()

    @staticmethod
    def doctype(name: str, sysid: str | None, pubid: str | None, has_internal_subset: bool) -> None:
        raise DTDForbidden(name, sysid, pubid)

    @staticmethod
    def entity(name: str, is_parameter_entity: bool, value: str | None, base: str | None, sysid: str | None,
               pubid: str | None, notation_name: str | None) -> None:
        raise EntitiesForbidden(name, value, base, sysid, pubid, notation_name)

    @staticmethod
    def unparsed_entity(name: str, base: str | None, sysid: str | None, pubid: str | None,
                        notation_name: str | None) -> None:
        raise EntitiesForbidden(name, None, base, sysid, pubid, notation_name)

    @staticmethod
    def external_reference(context: str, base: str | None, sysid: str | None, pubid: str | None) -> None:
        raise ExternalReferenceForbidden(context, base, sysid, pubid)


class _TooDeep(Exception):
    """An element deeper than :data:`~aeroexec.limits.MAX_NESTING`: reading stops at its line."""


def _refusal(exc: DefusedXmlException) -> str:
    if isinstance(exc, DTDForbidden):
        return (f"a DOCTYPE declaration (<!DOCTYPE {exc.name} ...>) is not allowed in a mission file: "
                "entities and external references are refused")
    if isinstance(exc, EntitiesForbidden):
        return f"the entity declaration {exc.name!r} is not allowed in a mission file (entities are refused)"
    if isinstance(exc, ExternalReferenceForbidden):
        return f"the external reference {exc.sysid!r} is not allowed in a mission file"
    return f"refused XML construct: {exc}"


def _unclosed(message: str, line: int, column: int, open_elements: list[_Element], data: bytes) -> str | None:
    """For an end tag that does not match, or a file that ends too soon: the element still open and its line,
    which is where the mistake usually is (a ``<TAKE_OFF>`` written without its ``/``); None otherwise."""
    if not open_elements or message not in ("mismatched tag", "no element found"):
        return None
    element = open_elements[-1]
    still_open = (f"<{element.tag}> opened at line {element.line} is still open (close it: <{element.tag} .../> "
                  f"or </{element.tag}>)")
    lines = data.split(b"\n")
    text = lines[line - 1] if 0 < line <= len(lines) else b""  # expat's column points into the end tag's name
    closing = next((m for m in re.finditer(rb"</\s*([^\s>]+)", text) if m.start() <= column <= m.end()), None)
    if message == "mismatched tag" and closing:
        return f"mismatched tag </{closing.group(1).decode('utf-8', 'replace')}>: {still_open}"
    return f"the file ends while {still_open}"


def parse_xml(data: bytes, file: str, lenient: list[tuple[str, int, str]] | None = None) -> _Element:
    """The element tree of an XML text, or a TreeFormatError naming the line where it stops being XML. With a
    ``lenient`` list, raw ``<`` and ``&`` in attribute values are read as BehaviorTree.CPP reads them, each place
    added to the list (``loaders.lenient_xml``)."""
    if lenient is not None:
        data, found = escape_attributes(data, file)
        lenient += found
    collector = _Collector()
    try:
        collector.parser.Parse(data, True)
    except DefusedXmlException as exc:
        raise TreeFormatError([(file, collector.line, _refusal(exc))]) from None
    except _TooDeep as exc:
        raise TreeFormatError([(file, collector.line, str(exc))]) from None
    except expat.ExpatError as exc:
        said = expat.ErrorString(exc.code)
        message = f"not well-formed XML: {_unclosed(said, exc.lineno, exc.offset, collector.stack, data) or said}"
        raise TreeFormatError([(file, exc.lineno, message)]) from None
    except (ValueError, LookupError) as exc:  # e.g. an unknown encoding
        raise TreeFormatError([(file, collector.line, f"not readable as XML: {exc}")]) from None
    if collector.root is None:
        raise TreeFormatError([(file, 0, "not XML: the file has no element")])
    return collector.root


class _XmlReader:
    """Reads a file and the files it includes, collecting trees and problems."""

    def __init__(self) -> None:
        self.problems: list[tuple[str, int, str]] = []
        self.warnings: list[tuple[str, int, str]] = []  # (file, line, message): read all the same
        self.not_portable: list[tuple[str, int, str]] = []  # read here, refused by BT.CPP 4.10 or Groot2
        self.trees: dict[str, TreeNode] = {}
        self.places: dict[str, tuple[str, int]] = {}  # tree ID -> (file, line)
        self.seen: set[str] = set()  # resolved paths already read
        self.subtree_models: dict[str, dict[str, str | None]] = {}  # <TreeNodesModel><SubTree>: port -> default

    def error(self, file: str, line: int, message: str) -> None:
        self.problems.append((file, line, message))

    def read_file(self, path: str, stack: tuple[str, ...], where: tuple[str, int]) -> None:
        """Reads an included file; ``where`` is the include element that names it."""
        key = os.path.realpath(path)
        if key in stack:
            chain = " -> ".join(os.path.basename(p) for p in (*stack, key))
            self.error(*where, f"include cycle: {chain}")
            return
        if key in self.seen:
            return
        try:
            data = read_bytes(path)
        except InputError as exc:
            self.error(*where, f"included file not found: {path}" if exc.missing
                       else f"cannot read the included file {path}: {exc.message}")
            return
        try:
            self.read_document(parse_xml(data, path, self.not_portable), path, (*stack, key))
        except TreeFormatError as exc:
            self.problems.extend(exc.problems)

    def read_document(self, root: _Element, file: str, stack: tuple[str, ...]) -> list[str]:
        """The IDs of the trees the document declares itself; included ones are added to ``self.trees``."""
        self.seen.add(stack[-1])
        if root.tag != "root":
            self.error(file, root.line, f"the document element must be <root BTCPP_format=\"4\">, not <{root.tag}>")
            return []
        version = root.attrs.get("BTCPP_format")
        if version is not None and version.strip() != "4":
            self.error(file, root.line, f"BTCPP_format=\"{version}\" is not supported: aeroexec reads "
                                        "BehaviorTree.CPP's format 4 (write BTCPP_format=\"4\")")
        declared: list[str] = []
        alone = sum(element.tag == "BehaviorTree" for element in root.children) == 1
        for element in root.children:
            if element.tag == "BehaviorTree":
                tree_id = self.read_tree(element, file, alone)
                if tree_id:
                    declared.append(tree_id)
            elif element.tag == "include":
                self.read_include(element, file, stack)
            elif element.tag == "TreeNodesModel":
                if any(other.tag == "TreeNodesModel" for other in root.children[:root.children.index(element)]):
                    self.not_portable.append((file, element.line, refused("Only a single node <TreeNodesModel> is "
                                                                          "supported")))
                self.read_models(element, file)
            elif element.tag == "SafetyRules":
                pass  # the operator's safety rules, read by engine/safety/declared.py (BT.CPP ignores it)
            else:
                self.error(file, element.line, f"unexpected <{element.tag}> in <root>: expected "
                                               f"<BehaviorTree>, <include> or <TreeNodesModel>"
                                               f"{suggestion(element.tag, _ROOT_CHILDREN)}")
        return declared

    def read_include(self, element: _Element, file: str, stack: tuple[str, ...]) -> None:
        if "ros_pkg" in element.attrs:
            self.error(file, element.line, "<include ros_pkg=...> is not supported: give path relative to this file")
            return
        target = element.attrs.get("path", "").strip()
        if not target:
            self.error(file, element.line, "<include> needs path=\"...\", the file to include")
            return
        path = os.path.normpath(os.path.join(os.path.dirname(file), target))
        if not path.lower().endswith(".xml"):
            self.error(file, element.line, f"<include> can only include XML files, not {target}")
            return
        self.read_file(path, stack, (file, element.line))

    def read_models(self, element: _Element, file: str) -> None:
        """The ports of the SubTrees the palette declares, with their defaults (BehaviorTree.CPP applies them)."""
        for model in element.children:
            if model.tag == SUBTREE and not model.attrs.get("ID"):  # BT.CPP 4.10's loadSubtreeModel throws
                self.not_portable.append((file, model.line, refused("Missing attribute 'ID' in SubTree element "
                                                                    "within TreeNodesModel")))
            if model.tag == SUBTREE and model.attrs.get("ID", "").strip():
                for port in model.children:
                    problem = port_name_problem(port.attrs.get("name", "")) if port.tag.endswith("_port") else None
                    if problem is not None:
                        self.not_portable.append((file, port.line, refused(problem)))
                self.subtree_models[model.attrs["ID"].strip()] = {
                    port.attrs["name"]: port.attrs.get("default") for port in model.children
                    if port.tag in ("input_port", "output_port", "inout_port") and port.attrs.get("name")}

    def read_tree(self, element: _Element, file: str, alone: bool = False) -> str | None:
        tree_id = element.attrs.get("ID", "").strip()
        if not tree_id and alone:  # BehaviorTree.CPP accepts one unnamed tree and names it so
            tree_id = f"BehaviorTree_{len(self.places)}"
        if not tree_id:
            self.error(file, element.line, "a <BehaviorTree> needs ID=\"...\" (only a file's one tree may go "
                                           "without)")
            return None
        written = element.attrs.get("ID", "")  # BT.CPP checks the ID as written: ID=" M" holds a space
        problem = model_name_problem(written) if written else None
        if problem is not None:
            self.not_portable.append((file, element.line, refused(problem)))
        nodes = [self.node(child, file) for child in element.children]
        if len(element.children) != 1:
            count = len(element.children)
            detail = "it is empty" if not count else f"it has {count} (put them under a Sequence)"
            self.error(file, element.line, f"BehaviorTree {tree_id} must have exactly one child node: {detail}")
        if tree_id in self.places:
            first = self.places[tree_id]
            self.error(file, element.line, f"BehaviorTree {tree_id} is declared twice (first at {first[0]}:{first[1]})")
            return None
        self.places[tree_id] = (file, element.line)
        if nodes and nodes[0] is not None:
            self.trees[tree_id] = nodes[0]
        return tree_id

    def node(self, element: _Element, file: str) -> TreeNode | None:
        if element.tag in ("BehaviorTree", "include", "root", "TreeNodesModel"):
            self.error(file, element.line, f"<{element.tag}> cannot be inside a tree")
            return None
        ports = dict(element.attrs)
        name = ports.pop("name", "")
        node_type, problem = resolve_type(element.tag, ports)
        if problem:
            self.error(file, element.line, problem)
        subtree = is_subtree(node_type)
        named = ports.get("ID", "") if subtree else element.tag  # as written (BT.CPP does not strip)
        problem = model_name_problem(named) if named and element.tag not in EXPLICIT_TAGS else None
        if problem is not None:
            self.not_portable.append((file, element.line, refused(problem)))
        if subtree:
            if not ports.get("ID", "").strip():
                self.error(file, element.line, "a <SubTree> needs ID=\"...\", the BehaviorTree it runs")
            name = name or ports.get("ID", "")
        if element.tag == CONDITION and node_type == element.tag:  # the node type's word as a tag
            self.warnings.append((file, element.line, "<Condition belief=...> is aeroexec's old spelling, refused "
                                                      "by BehaviorTree.CPP and Groot2: write <CheckBelief "
                                                      "belief=\"...\"/>"))
        children = [self.node(child, file) for child in element.children]
        return TreeNode(node_type, name, ports, [c for c in children if c is not None], file, element.line,
                        tag=element.tag, named="name" in element.attrs)


def _apply_subtree_models(reader: _XmlReader) -> None:
    """Ports a SubTree leaves out take their ``<TreeNodesModel>`` default (a port without one must be given)."""
    for root in reader.trees.values():
        for node in root.walk():
            model = reader.subtree_models.get(node.ports.get("ID", "").strip()) if is_subtree(node.type) else None
            if not model or node.ports.get("_autoremap", "").strip().lower() == "true":
                continue
            for port, default in model.items():
                if port in node.ports:
                    continue
                if default is None:
                    tree = node.ports["ID"]
                    reader.error(node.file, node.line, f"In the <TreeNodesModel> the <SubTree ID=\"{tree}\"> is "
                                                       f"defining a mandatory port called [{port}], but you are not "
                                                       "remapping it")
                else:
                    node.ports[port] = default


def _main_tree(reader: _XmlReader, root: _Element, file: str, declared: list[str]) -> str:
    main = root.attrs.get("main_tree_to_execute", "").strip() if root.tag == "root" else ""
    known = list(reader.places)
    if main:
        if main not in reader.places:
            reader.error(file, root.line, f"main_tree_to_execute names {main}, but no BehaviorTree has that ID"
                                          f"{suggestion(main, known)} (trees: {', '.join(known) or 'none'})")
        return main
    if len(declared) == 1:
        return declared[0]
    if len(known) == 1:
        return known[0]
    if not known:
        models = any(child.tag == "TreeNodesModel" for child in root.children)
        reader.error(file, root.line, "the file declares no <BehaviorTree>" + (
            ": it holds only a <TreeNodesModel>, the models of nodes (a palette for Groot and the trees that use "
            "them), no tree to run" if models else ""))
    elif root.tag == "root":
        reader.error(file, root.line, f"main_tree_to_execute is missing and there are {len(known)} trees "
                                      f"({', '.join(known)}): say which one to execute")
    return ""


def read_xml(data: bytes | str, file: str = "<xml>") -> TreeDocument:
    """A mission from XML text; ``file`` names it in problems and anchors relative includes."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    reader = _XmlReader()
    root = parse_xml(raw, file, reader.not_portable)
    declared = reader.read_document(root, file, (os.path.realpath(file),))
    main = _main_tree(reader, root, file, declared)
    _apply_subtree_models(reader)
    if reader.problems:
        raise TreeFormatError(reader.problems)
    lines = {tree_id: line for tree_id, (_, line) in reader.places.items()}
    logger.debug("read %d behavior trees from %s (main %s)", len(reader.trees), file, main)
    return TreeDocument(reader.trees, main, file, lines, reader.warnings, reader.not_portable)


