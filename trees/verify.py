"""Verification of a behavior-tree mission before flight: every problem found without flying, with file:line.

``verify_document(document, catalog)`` reports, in the paper's words (Table 1) where they apply: the main tree
missing; unknown node types (with a suggestion); child counts per node type; unknown and missing ports of the
built-in nodes and their values, converted as BehaviorTree.CPP converts them as it loads a tree (the node classes'
port declarations say which); behavior arguments against the catalog (WRONG_FORMAT, WRONG_VALUE); belief
expressions' syntax and predicates; scripts; SubTree references and cycles; the blackboard (``trees.blackboard_check``:
keys read before any node writes them, script variables nothing writes, entries ports give two types); what the
loader warned of; and WRONG_SEQUENCE along every path (see ``trees.sequence_check`` for the policy).
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterable

from aeroexec.beliefs import BeliefError, RuleError, parse_expression, parse_rules
from aeroexec.beliefs.parser import check_expression as checked_expression
from aeroexec.engine.catalog import BehaviorCatalog, BehaviorSpecialist, default_catalog
from aeroexec.engine.catalog.descriptors import PredicateDeclaration
from aeroexec.engine.catalog.vocabulary import check_rules
from aeroexec.engine.catalog.world_check import WorldMap
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_VALUE, MissionProblem, SpecificationError
from aeroexec.engine.yaml_nodes import suggestion
from aeroexec.trees.blackboard_check import BlackboardChecker
from aeroexec.trees.conversions import ANY, BOOL, DOUBLE, INT, STRING, UNSIGNED, ConversionError, convert, queue_items
from aeroexec.trees.model import COMMON_ATTRIBUTES, POSTCONDITIONS, PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.ports import OPTIONS, bare_key, port_errors
from aeroexec.trees.runtime.kinds import NodeKind, kind_of, kinds
from aeroexec.trees.runtime.manifests import ACTION, NodeManifest, Port
from aeroexec.trees.script import ScriptError, compile_script
from aeroexec.trees.sequence_check import SequenceChecker
from aeroexec.trees.subtrees import check_expansion, check_subtree_paths

from aeroexec.limits import MAX_NESTING

Problem = MissionProblem
#: aeroexec's checks beyond BT.CPP's conversion: the least count that means something, the statuses a node may
#: answer with (BT.CPP converts IDLE too, then throws when a node returns it).
_MINIMUM = {"num_cycles": -1, "num_attempts": -1}
_STATUS_PORTS = {"else": ("SUCCESS", "FAILURE", "SKIPPED", "RUNNING"), "if_empty": ("SUCCESS", "FAILURE", "SKIPPED")}
_EXPECTED = {INT: "an integer", UNSIGNED: "an integer of at least 0", DOUBLE: "a number", BOOL: "true or false"}


class TreeVerifier:
    """Collects every problem of one document."""

    def __init__(self, document: TreeDocument, catalog: BehaviorCatalog | None = None,
                 known_keys: Iterable[str] = (), world: WorldMap | None = None) -> None:
        self.document = document
        self.catalog = catalog if catalog is not None else default_catalog()
        self.specialist = BehaviorSpecialist(self.catalog, world)
        self.known_keys = set(known_keys)
        self.problems: list[Problem] = []
        self._seen: set[tuple[str, int, str]] = set()
        self._node_types = sorted({*kinds(), *self.catalog.behaviors})
        self.vocabulary = {p.name: p.arity for p in self.catalog.predicates.values()}
        for root in document.trees.values():  # AddBelief declares the predicates the catalog does not know
            for node in root.walk():
                kind = kind_of(node.type)
                for port in kind.manifest.ports if kind is not None else ():
                    if port.language == "new_belief":
                        self.vocabulary.update(_new_predicates(node.ports.get(port.name, ""), self.vocabulary))
                    elif port.language == "rules":  # what its rules derive, and its facts' predicates
                        with contextlib.suppress(BeliefError):
                            self.vocabulary.update({r.head.name: r.head.arity
                                                    for r in parse_rules(node.ports.get(port.name, ""))})

    def report(self, node: TreeNode | None, message: str, kind: str = WRONG_FORMAT, severity: str = "error") -> None:
        file = (node.file if node is not None else "") or self.document.file
        line = node.line if node is not None else 0
        if (file, line, message) not in self._seen:
            self._seen.add((file, line, message))
            self.problems.append(Problem(severity, message, file, line, kind))

    def verify(self) -> list[Problem]:
        document = self.document
        for file, line, message in (*document.warnings, *document.not_portable):  # counted with the others
            self.problems.append(Problem("warning", message, file, line, WRONG_FORMAT))
        if document.main not in document.trees:
            self.problems.append(Problem("error", f"The main tree {document.main} does not exist"
                                         f"{suggestion(document.main, document.trees)}", document.file,
                                         0, WRONG_FORMAT))
        for tree_id, root in document.trees.items():
            for node in root.walk():
                self.check_node(node)
            self.check_cycles(tree_id)
        if document.main in document.trees and check_expansion(self.document, self.report):
            BlackboardChecker(document, self.known_keys, self.report).check()
            check_subtree_paths(self.document, self.report)
            SequenceChecker(document, self.specialist, self.report).check()
        self.problems.sort(key=lambda p: (p.file, p.line))
        return self.problems

    # -- one node ------------------------------------------------------------------------------
    def check_node(self, node: TreeNode) -> None:
        kind = kind_of(node.type)
        behavior = self.catalog.behavior(node.type)
        if kind is None and behavior is None:
            self.report(node, f"The behavior {node.type} does not exist{suggestion(node.type, self._node_types)}")
        else:
            shape = kind.manifest if kind is not None else NodeManifest(ACTION)  # a catalog behavior is a leaf
            self.check_children(node, shape.min_children, shape.max_children, shape.children_text())
        for attribute in PRECONDITIONS:
            if attribute in node.ports:
                self.check_condition(node, attribute, node.ports[attribute])
        written = [p for p in kind.manifest.ports if p.language and p.name in node.ports] if kind is not None else []
        for port in written:  # what the kind's ports are written in: belief expressions, rules, then scripts
            if port.language in ("belief", "query", "new_belief"):
                self.check_expression(node, port.name, node.ports[port.name], new=port.language == "new_belief")
            elif port.language == "rules":
                self.check_rules(node, node.ports[port.name])
        for port in written:
            if port.language == "script":
                self.check_script(node, port.name, node.ports[port.name])
        for attribute in POSTCONDITIONS:
            if attribute in node.ports:
                self.check_script(node, attribute, node.ports[attribute])
        if kind is not None:
            self.check_built_in(node, kind)
        elif behavior is not None:
            self.request_problems(node, port_errors(self.specialist, node.type, node.ports))

    def check_children(self, node: TreeNode, low: int, high: int | None, text: str) -> None:
        count = len(node.children)
        if count < low or (high is not None and count > high):
            self.report(node, f"The node {node.type} must have {text}, not {count}")

    def check_built_in(self, node: TreeNode, kind: NodeKind) -> None:
        declared = kind.ports
        asked = node.ports.get(kind.behavior_port, "").strip() if kind.behavior_port else ""
        extra = () if not kind.behavior_port else tuple(p for p in node.ports if p not in declared)
        for port in node.ports:
            if port in COMMON_ATTRIBUTES or port in declared or port in extra or kind.subtree:
                continue
            self.report(node, f"The port {port} of node {node.type} does not exist"
                              f"{suggestion(port, declared) if declared else ' (it has no ports)'}")
        for port in declared.values():
            self.check_port(node, port)
        if kind.counts_children:
            self.check_counts(node, kind)
        if kind.subtree:
            tree = node.ports.get("ID", "").strip()
            if tree and tree not in self.document.trees:
                self.report(node, f"The tree {tree} does not exist{suggestion(tree, self.document.trees)}")
        if asked:
            own = tuple(p for p in declared if p not in OPTIONS)  # its own ports; the options go to the behavior
            self.request_problems(node, port_errors(self.specialist, asked, node.ports, own))

    def check_port(self, node: TreeNode, port: Port) -> None:
        """A built-in node's port: written when it must be, its text of the port's type (as BT.CPP converts it when
        it loads the tree); a ``{key}`` is read in flight."""
        text = node.ports.get(port.name)
        if text is None or (port.required and not text.strip() and port.type in (STRING, ANY) and not port.empty):
            if port.required:
                self.report(node, f"The node {node.type} needs the port {port.name}")
            return
        if bare_key(text) is not None or port.type in (STRING, ANY):
            if port.name == "queue" and bare_key(text) is None:
                self.check_queue(node, text)
            return
        allowed = _STATUS_PORTS.get(port.name, ())
        try:  # a status port's text is one it allows (statuses, as text: converting them would load py_trees)
            value = text if allowed else convert(text, port.type)
        except ConversionError:
            value = None
        wrong = (value is None or bool(allowed and text not in allowed)
                 or (port.name in _MINIMUM and value < _MINIMUM[port.name]))
        if wrong:
            expected = ", ".join(allowed) if allowed else _EXPECTED.get(port.type, port.type)
            if port.name in _MINIMUM:
                expected += " (-1: forever)"
            self.report(node, f"The value {text} of port {port.name} of node {node.type} is not correct ({expected} "
                              f"is expected)", WRONG_VALUE)
        elif port.type in (INT, UNSIGNED) and not re.fullmatch(r"-?\d+", text):
            self.report(node, f"The value {text} of port {port.name} of node {node.type} is read as {value} "
                              f"(BehaviorTree.CPP reads the integer the text starts with)", WRONG_VALUE, "warning")

    def check_queue(self, node: TreeNode, text: str) -> None:
        value = kind.ports.get("value") if (kind := kind_of(node.type)) is not None else None
        item = value.type if value is not None and value.type in (INT, DOUBLE, BOOL) else STRING  # the items' type
        try:
            queue_items(text, item)
        except ConversionError as error:
            self.report(node, f"The value {text} of port queue of node {node.type} is not correct ({item} items "
                              f"separated by ; are expected: {error})", WRONG_VALUE)

    def check_counts(self, node: TreeNode, kind: NodeKind) -> None:
        """The ports that count a node's children (a Parallel's success_count, failure_count) against them."""
        count = len(node.children)
        for port in kind.counts_children:
            text = node.ports.get(port, kind.ports[port].default or "")
            try:
                value = convert(text, INT)
            except ConversionError:
                continue  # reported by check_port
            needed = max(count + value + 1, 0) if value < 0 else value
            if needed > count or needed == 0:
                self.report(node, f"The value {text} of port {port} of node {node.type} is not correct "
                                  f"(it has {count} children)", WRONG_VALUE)

    def check_expression(self, node: TreeNode, attribute: str, text: str, new: bool = False) -> None:
        """A belief expression (``new``: a belief the node adds, whose values nothing needs to write)."""
        if not text.strip():
            self.report(node, f"The {attribute} of node {node.type} is empty (a belief expression is expected)")
            return
        try:
            expression = checked_expression(_placeholders(text), self.vocabulary)  # as a memory checks it
        except BeliefError as error:
            self.report(node, error.message, WRONG_FORMAT)
            return
        if not new:
            for message in self.specialist.unwritten_values(expression):
                self.report(node, message, WRONG_VALUE, "warning")

    def check_rules(self, node: TreeNode, text: str) -> None:
        """AddRule's rules: read and checked against the catalog's vocabulary (each problem at the node's line)."""
        try:
            rules = parse_rules(text, node.file or self.document.file, node.line or 1)
            derived = {r.head.name for r in rules if r.body.literals}
            known = {name: PredicateDeclaration(name, arity) for name, arity in self.vocabulary.items()
                     if name not in derived}  # the mission's own (AddBelief, facts) as stored ones
            problems = check_rules({**known, **self.catalog.predicates}, [*self.catalog.rules, *rules])
        except RuleError as error:
            problems = error.problems
        for problem in problems:
            self.report(node, f"AddRule: {problem.message}")

    def check_condition(self, node: TreeNode, attribute: str, text: str) -> None:
        """A pre-condition: a script, or else the belief expression aeroexec took there before."""
        try:
            compile_script(text)
        except ScriptError:
            self.report(node, f"The {attribute} of node {node.type} is a belief expression, aeroexec's old reading "
                              f"(BehaviorTree.CPP reads a script there): write {attribute}='belief(\"{text}\")'",
                        WRONG_FORMAT, "warning")
            self.check_expression(node, attribute, text)

    def check_script(self, node: TreeNode, attribute: str, text: str) -> None:
        try:
            compile_script(text)
        except ScriptError as error:
            self.report(node, f"The {attribute} of node {node.type} is not a script: {error}")

    def request_problems(self, node: TreeNode, errors: list[SpecificationError]) -> None:
        for error in errors:
            self.report(node, error.message, error.kind)

    # -- subtrees --------------------------------------------------------------------------------
    def check_cycles(self, tree_id: str) -> None:
        visited: set[str] = set()  # each tree once: a tree used many times is not walked again

        def visit(tree: str, path: tuple[str, ...]) -> None:
            visited.add(tree)
            for node in self.document.trees[tree].walk():
                if (kind := kind_of(node.type)) is None or not kind.subtree:
                    continue
                target = node.ports.get("ID", "").strip()
                if target == tree_id:
                    self.report(node, f"The tree {tree_id} includes itself "
                                      f"({' -> '.join((*path, target))})")
                elif target in self.document.trees and target not in visited and len(path) < MAX_NESTING:
                    visit(target, (*path, target))

        visit(tree_id, (tree_id,))


def _placeholders(text: str) -> str:
    """A belief expression with each ``{key}`` (known in flight) as an anonymous variable."""
    return re.sub(r"\{[^{}]+\}", "_", text)


def _new_predicates(text: str, known: dict[str, int]) -> dict[str, int]:
    try:
        expression = parse_expression(_placeholders(text))
    except BeliefError:
        return {}
    return {name: arity for name, arity in expression.predicates if name not in known}


def verify_document(document: TreeDocument, catalog: BehaviorCatalog | None = None,
                    known_keys: Iterable[str] = (), world: WorldMap | None = None) -> list[Problem]:
    """Every problem of a tree mission, sorted by place; ``known_keys`` are blackboard keys set before it runs;
    with a ``world``, literal destinations and paths are checked against its bounds and obstacles."""
    return TreeVerifier(document, catalog, known_keys, world).verify()


def verify_leaves(leaves: Iterable[TreeNode], catalog: BehaviorCatalog | None = None, file: str = "") -> list[Problem]:
    """The problems of single nodes (behavior names, arguments, belief expressions) of a file that could not be
    read whole: the catalog's word on them comes with the reader's errors."""
    leaves = list(leaves)
    root = TreeNode("Sequence", "", {}, leaves, file, 0)
    verifier = TreeVerifier(TreeDocument({"leaves": root}, "leaves", file), catalog)
    for node in leaves:
        verifier.check_node(node)
    return sorted(verifier.problems, key=lambda p: (p.file, p.line))
