"""Verification of a behavior-tree mission before flight: every problem found without flying, with file:line.

``verify_document(document, catalog)`` reports, in the paper's words (Table 1) where they apply: the main tree
missing; unknown node types (with a suggestion); child counts per node type; unknown and missing ports of the
built-in nodes and their values; behavior arguments against the catalog (WRONG_FORMAT, WRONG_VALUE); belief
expressions' syntax and predicates; SubTree references and cycles; blackboard keys read before any node can
write them; and WRONG_SEQUENCE along every path (see ``trees.sequence_check`` for the policy).

Blackboard keys: QueryBelief writes its expression's variables, AskBehavior its ``result`` key, a SubTree's
literal ports are written when it starts and ``{key}`` ports remap keys to the parent's. A read is accepted when
some node writes the key earlier in tick order, or anywhere inside a loop or Parallel around the read.
"""

from __future__ import annotations

import bisect
import contextlib
import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from aeroexec.beliefs import BeliefError, BeliefMemory, parse_expression
from aeroexec.engine.catalog import BehaviorCatalog, BehaviorSpecialist, default_catalog
from aeroexec.engine.catalog.world_check import WorldMap
from aeroexec.engine.errors import WRONG_FORMAT, WRONG_VALUE, SpecificationError
from aeroexec.engine.missions.check import MissionProblem
from aeroexec.engine.yaml_nodes import suggestion
from aeroexec.trees.model import COMMON_ATTRIBUTES, POSTCONDITIONS, PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.ports import bare_key, output_key, parse_number, port_errors, template_keys
from aeroexec.trees.runtime.registry import BUILT_IN, LOOPING, children_text, ports_of
from aeroexec.trees.script import ScriptError, compile_script
from aeroexec.trees.sequence_check import SequenceChecker
from aeroexec.trees.subtrees import check_expansion, check_subtree_paths

from aeroexec.limits import MAX_NESTING

Problem = MissionProblem
_INTEGER_PORTS = {"num_cycles": -1, "num_attempts": -1, "msec": 0, "delay_msec": 0, "max_failures": None}
_FROM_BLACKBOARD = ("num_cycles", "num_attempts")  # integer ports that may read {key} in flight
_OUTPUTS = {("AskBehavior", "result"), ("SetBlackboard", "output_key")}  # ports that write, never read
_STATUS_PORTS = {"else": ("SUCCESS", "FAILURE", "SKIPPED", "RUNNING"), "if_empty": ("SUCCESS", "FAILURE", "SKIPPED")}
_SCRIPT_PORTS = ("code", "if", *POSTCONDITIONS)
_SCRIPT_NODES = ("Script", "ScriptCondition", "Precondition")
BELIEF_LEAF_TYPES = ("Condition", "CheckBelief", "QueryBelief", "AddBelief", "RemoveBelief")


@dataclass
class _Scope:
    """A blackboard scope of the main tree or of one SubTree use, as verification sees it."""

    parent: _Scope | None = None
    remap: dict[str, str] = field(default_factory=dict)
    autoremap: bool = False
    literals: set[str] = field(default_factory=set)

    def resolve(self, key: str) -> tuple[int, str]:
        if key in self.remap and self.parent is not None:
            return self.parent.resolve(self.remap[key])
        if key in self.literals or not self.autoremap or self.parent is None:
            return id(self), key
        return self.parent.resolve(key)


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
        self._node_types = sorted({*BUILT_IN, *self.catalog.behaviors})
        self.vocabulary = {p.name: p.arity for p in self.catalog.predicates.values()}
        for root in document.trees.values():  # AddBelief declares the predicates the catalog does not know
            for node in root.walk():
                if node.type == "AddBelief":
                    self.vocabulary.update(_new_predicates(node.ports.get("belief", ""), self.vocabulary))

    def report(self, node: TreeNode | None, message: str, kind: str = WRONG_FORMAT, severity: str = "error") -> None:
        file = (node.file if node is not None else "") or self.document.file
        line = node.line if node is not None else 0
        if (file, line, message) not in self._seen:
            self._seen.add((file, line, message))
            self.problems.append(Problem(severity, message, file, line, kind))

    def verify(self) -> list[Problem]:
        document = self.document
        if document.main not in document.trees:
            self.problems.append(Problem("error", f"The main tree {document.main} does not exist"
                                         f"{suggestion(document.main, document.trees)}", document.file,
                                         0, WRONG_FORMAT))
        for tree_id, root in document.trees.items():
            for node in root.walk():
                self.check_node(node)
            self.check_cycles(tree_id)
        if document.main in document.trees and check_expansion(self.document, self.report):
            self.check_blackboard()
            check_subtree_paths(self.document, self.report)
            SequenceChecker(document, self.specialist, self.report).check()
        self.problems.sort(key=lambda p: (p.file, p.line))
        return self.problems

    # -- one node ------------------------------------------------------------------------------
    def check_node(self, node: TreeNode) -> None:
        kind = node.type
        spec = BUILT_IN.get(kind)
        behavior = self.catalog.behavior(kind)
        if spec is None and behavior is None:
            self.report(node, f"The behavior {kind} does not exist{suggestion(kind, self._node_types)}")
        else:
            self.check_children(node, spec.min_children if spec else 0, spec.max_children if spec else 0,
                                children_text(kind) if spec else "no children")
        for attribute in PRECONDITIONS:
            if attribute in node.ports:
                self.check_condition(node, attribute, node.ports[attribute])
        if "belief" in node.ports and kind in BELIEF_LEAF_TYPES:
            self.check_expression(node, "belief", node.ports["belief"])
        for attribute in _SCRIPT_PORTS:
            if attribute in node.ports and (attribute in POSTCONDITIONS or kind in _SCRIPT_NODES):
                self.check_script(node, attribute, node.ports[attribute])
        if spec is not None:
            self.check_built_in(node)
        elif behavior is not None:
            self.request_problems(node, port_errors(self.specialist, kind, node.ports))

    def check_children(self, node: TreeNode, low: int, high: int | None, text: str) -> None:
        count = len(node.children)
        if count < low or (high is not None and count > high):
            self.report(node, f"The node {node.type} must have {text}, not {count}")

    def check_built_in(self, node: TreeNode) -> None:
        kind = node.type
        declared = ports_of(kind)
        extra = () if kind != "AskBehavior" else tuple(self._ask_arguments(node))
        for port in node.ports:
            if port in COMMON_ATTRIBUTES or port in declared or port in extra or kind == "SubTree":
                continue
            self.report(node, f"The port {port} of node {kind} does not exist"
                              f"{suggestion(port, declared) if declared else ' (it has no ports)'}")
        for port in declared.values():
            if port.required and not node.ports.get(port.name, "").strip():
                self.report(node, f"The node {kind} needs the port {port.name}")
        for port, minimum in _INTEGER_PORTS.items():
            if port in declared and node.ports.get(port, "").strip():
                self.check_integer(node, port, minimum)
        if kind == "Parallel":
            self.check_parallel(node)
        for port, allowed in _STATUS_PORTS.items():
            if port in declared and node.ports.get(port, "").strip() not in ("", *allowed):
                self.report(node, f"The value {node.ports[port]} of port {port} of node {kind} is not correct "
                                  f"({', '.join(allowed)} is expected)", WRONG_VALUE)
        if kind == "RunOnce" and node.ports.get("then_skip", "true").strip().lower() not in ("true", "false"):
            self.report(node, f"The value {node.ports['then_skip']} of port then_skip of node RunOnce is not "
                              f"correct (true or false is expected)", WRONG_VALUE)
        if kind == "SubTree":
            tree = node.ports.get("ID", "").strip()
            if tree and tree not in self.document.trees:
                self.report(node, f"The tree {tree} does not exist{suggestion(tree, self.document.trees)}")
        if kind == "AskBehavior":
            name = node.ports.get("behavior", "").strip()
            if name:
                self.request_problems(node, port_errors(self.specialist, name, node.ports, ("behavior", "result")))

    def _ask_arguments(self, node: TreeNode) -> list[str]:
        return [p for p in node.ports if p not in ("behavior", "result")]

    def check_integer(self, node: TreeNode, port: str, minimum: int | None) -> int | None:
        text = node.ports[port]
        if bare_key(text) is not None and port in _FROM_BLACKBOARD:  # read from the blackboard in flight
            return None
        value = parse_number(text)
        if not isinstance(value, int) or (minimum is not None and value < minimum):
            expected = ("" if minimum is None else f"of at least {minimum} " if minimum >= 0 else "(-1: forever) ")
            self.report(node, f"The value {text} of port {port} of node {node.type} is not correct (an integer "
                              f"{expected}is expected)", WRONG_VALUE)
            return None
        return value

    def check_parallel(self, node: TreeNode) -> None:
        count = len(node.children)
        for port, default in (("success_count", -1), ("failure_count", 1)):
            text = node.ports.get(port, "").strip()
            value = parse_number(text) if text else default
            if not isinstance(value, int):
                self.report(node, f"The value {text} of port {port} of node Parallel is not correct "
                                  f"(an integer is expected)", WRONG_VALUE)
                continue
            needed = max(count + value + 1, 0) if value < 0 else value
            if needed > count or needed == 0:
                self.report(node, f"The value {text or default} of port {port} of node Parallel is not correct "
                                  f"(it has {count} children)", WRONG_VALUE)

    def check_expression(self, node: TreeNode, attribute: str, text: str) -> None:
        if not text.strip():
            self.report(node, f"The {attribute} of node {node.type} is empty (a belief expression is expected)")
            return
        try:
            expression = BeliefMemory(predicates=self.vocabulary).check(_placeholders(text))
        except BeliefError as error:
            self.report(node, error.message, WRONG_FORMAT)
            return
        if node.type != "AddBelief":
            for message in self.specialist.unwritten_values(expression):
                self.report(node, message, WRONG_VALUE, "warning")

    def check_condition(self, node: TreeNode, attribute: str, text: str) -> None:
        """A pre-condition: a script, or else the belief expression aeroexec took there before."""
        try:
            compile_script(text)
        except ScriptError:
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
                if node.type != "SubTree":
                    continue
                target = node.ports.get("ID", "").strip()
                if target == tree_id:
                    self.report(node, f"The tree {tree_id} includes itself "
                                      f"({' -> '.join((*path, target))})")
                elif target in self.document.trees and target not in visited and len(path) < MAX_NESTING:
                    visit(target, (*path, target))

        visit(tree_id, (tree_id,))

    def check_blackboard(self) -> None:
        writes: list[tuple[int, tuple[int, str]]] = []  # (position, resolved key)
        reads: list[tuple[int, tuple[int, str], str, TreeNode, list[tuple[int, int]]]] = []
        root_scope = _Scope()
        known = {root_scope.resolve(k) for k in self.known_keys}
        position = [0]

        def walk(node: TreeNode, scope: _Scope, loops: list[tuple[int, int]], stack: tuple[str, ...]) -> None:
            position[0] += 1
            here = position[0]
            for key in self._reads(node):
                reads.append((here, scope.resolve(key), key, node, loops))
            for key in self._writes(node):
                writes.append((here, scope.resolve(key)))
            span: list[tuple[int, int]] = loops
            if node.type in LOOPING or node.type == "Parallel":
                region = [here, 0]
                span = [*loops, region]  # type: ignore[list-item]
            if node.type == "SubTree":
                target = node.ports.get("ID", "").strip()
                if target in self.document.trees and target not in stack:
                    inner = self._subtree_scope(node, scope)
                    writes.extend((here, inner.resolve(port)) for port in inner.literals)
                    walk(self.document.trees[target], inner, span, (*stack, target))
            for child in node.children:
                walk(child, scope, span, stack)
            if span is not loops:
                span[-1][1] = position[0]  # type: ignore[index]

        walk(self.document.root, root_scope, [], (self.document.main,))
        written: dict[tuple[int, str], list[int]] = {}  # key -> the positions writing it, in order (walk order)
        for at, key in writes:
            written.setdefault(key, []).append(at)
        for here, key, text, node, loops in reads:
            if key in known:
                continue
            places = written.get(key, [])
            if places and places[0] < here:
                continue
            if any(bisect.bisect_left(places, start) < bisect.bisect_right(places, end) for start, end in loops):
                continue
            mapped = f" (mapped to {key[1]})" if key[1] != text else ""
            self.report(node, f"The blackboard key {text}{mapped} is read before any node writes it")

    def _subtree_scope(self, node: TreeNode, parent: _Scope) -> _Scope:
        scope = _Scope(parent, autoremap=node.ports.get("_autoremap", "").strip().lower() in ("true", "1", "yes"))
        for port, text in node.ports.items():
            if port in COMMON_ATTRIBUTES:
                continue
            key = bare_key(text)
            if key is None:
                scope.literals.add(port)
            else:
                scope.remap[port] = port if key == "=" else key
        return scope

    @staticmethod
    def _reads(node: TreeNode) -> list[str]:
        keys: list[str] = []
        for port, text in node.ports.items():
            if node.type == "SubTree" and port not in PRECONDITIONS:
                continue
            if (node.type, port) in _OUTPUTS or (node.type.startswith("Loop") and port == "value"):
                continue
            keys += template_keys(text)
        return keys

    @staticmethod
    def _writes(node: TreeNode) -> list[str]:
        keys: list[str] = []
        for port in ("code", *PRECONDITIONS, *POSTCONDITIONS):
            if port in node.ports:
                with contextlib.suppress(ScriptError):  # reported by check_script
                    keys += compile_script(node.ports[port]).writes
        if node.type == "SetBlackboard":
            keys.append(output_key(node.ports.get("output_key", "")))
        if node.type in ("LoopInt", "LoopDouble", "LoopString", "LoopBool") and node.ports.get("value"):
            keys.append(output_key(node.ports["value"]))
        return keys + TreeVerifier._leaf_writes(node)

    @staticmethod
    def _leaf_writes(node: TreeNode) -> list[str]:
        if node.type == "QueryBelief":
            return [v.lstrip("?") for v in re.findall(r"\?[A-Za-z_][A-Za-z0-9_]*", node.ports.get("belief", ""))]
        if node.type == "AskBehavior" and node.ports.get("result", "").strip():
            return [output_key(node.ports["result"])]
        return []


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
