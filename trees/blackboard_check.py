"""The blackboard of a tree mission as verification sees it, each scope (the main tree, each SubTree use) resolved
as the runtime resolves it.

* A ``{key}`` a port reads is an error when no node writes the key earlier in tick order, nor anywhere inside a loop
  or Parallel around the read: QueryBelief writes its expression's variables, AskBehavior its ``result``, a Loop its
  ``value``, SetBlackboard its ``output_key``, a script what it assigns, a SubTree's literal ports are written when it
  starts and its ``{key}`` ports remap keys to the parent's.
* A variable a script reads that no node writes anywhere is a warning: the run fails there (BT.CPP's "Variable not
  found") unless the embedding sets it.
* Two ports of different types on one entry are an error: BehaviorTree.CPP refuses the tree as it loads it.
"""

from __future__ import annotations

import bisect
import contextlib
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from aeroexec.engine.errors import WRONG_FORMAT
from aeroexec.trees.conversions import ANY, compatible, type_conflict
from aeroexec.trees.model import COMMON_ATTRIBUTES, POSTCONDITIONS, PRECONDITIONS, TreeDocument, TreeNode
from aeroexec.trees.ports import bare_key, output_key, template_keys
from aeroexec.trees.runtime.kinds import kind_of, ports_in
from aeroexec.trees.script import Script, ScriptError, compile_script

Key = tuple[int, str]  # (scope, name) as resolved
Report = Callable[..., None]  # report(node, message, kind, severity)


@dataclass
class _Scope:
    """A blackboard scope of the main tree or of one SubTree use."""

    parent: _Scope | None = None
    remap: dict[str, str] = field(default_factory=dict)
    autoremap: bool = False
    literals: set[str] = field(default_factory=set)

    def resolve(self, key: str) -> Key:
        if key.startswith("@"):  # the root blackboard's key
            root = self
            while root.parent is not None:
                root = root.parent
            return id(root), key[1:]
        if key in self.remap and self.parent is not None:
            return self.parent.resolve(self.remap[key])
        if key in self.literals or not self.autoremap or self.parent is None or key[:1] == "_":  # private
            return id(self), key
        return self.parent.resolve(key)

    @classmethod
    def of_subtree(cls, node: TreeNode, parent: _Scope) -> _Scope:
        scope = cls(parent, autoremap=node.ports.get("_autoremap", "").strip().lower() in ("true", "1", "yes"))
        for port, text in node.ports.items():
            if port in COMMON_ATTRIBUTES:
                continue
            key = bare_key(text)
            if key is None:
                scope.literals.add(port)
            else:
                scope.remap[port] = port if key == "=" else key
        return scope


class BlackboardChecker:
    """Walks the main tree, SubTrees expanded where used, in tick order."""

    def __init__(self, document: TreeDocument, known_keys: Iterable[str], report: Report) -> None:
        self.document, self.report = document, report
        self.known_keys = set(known_keys)
        self.writes: list[tuple[int, Key]] = []  # (position, key)
        self.reads: list[tuple[int, Key, str, TreeNode, list[tuple[int, int]]]] = []
        self.script_reads: list[tuple[Key, str, TreeNode]] = []
        self.types: dict[Key, str] = {}
        self.position = 0

    def check(self) -> None:
        root = _Scope()
        self.walk(self.document.root, root, [], (self.document.main,))
        known = {root.resolve(k) for k in self.known_keys}
        written: dict[Key, list[int]] = {}  # key -> the positions writing it, in walk order
        for at, key in self.writes:
            written.setdefault(key, []).append(at)
        for here, key, text, node, loops in self.reads:
            places = written.get(key, [])
            if key in known or (places and places[0] < here):
                continue
            if any(bisect.bisect_left(places, start) < bisect.bisect_right(places, end) for start, end in loops):
                continue
            mapped = f" (mapped to {key[1]})" if key[1] != text else ""
            self.report(node, f"The blackboard key {text}{mapped} is read before any node writes it", WRONG_FORMAT)
        for key, text, node in self.script_reads:
            if key not in known and key not in written:
                self.report(node, f"The script variable {text} is read but no node writes it (the run fails there: "
                                  f"\"Variable not found: {text}\")", WRONG_FORMAT, "warning")

    def walk(self, node: TreeNode, scope: _Scope, loops: list[tuple[int, int]], stack: tuple[str, ...]) -> None:
        self.position += 1
        here = self.position
        self.check_types(node, scope)
        for key in self.port_reads(node):
            self.reads.append((here, scope.resolve(key), key, node, loops))
        for script in self.scripts(node):
            self.script_reads.extend((scope.resolve(name), name, node) for name in script.reads)
            self.writes.extend((here, scope.resolve(name)) for name in script.writes)
        self.writes.extend((here, scope.resolve(key)) for key in self.port_writes(node))
        span: list[tuple[int, int]] = loops
        kind = kind_of(node.type)
        if kind is not None and (kind.loops or kind.concurrent):
            span = [*loops, [here, 0]]  # type: ignore[list-item]
        if kind is not None and kind.subtree:
            target = node.ports.get("ID", "").strip()
            if target in self.document.trees and target not in stack:
                inner = _Scope.of_subtree(node, scope)
                self.writes.extend((here, inner.resolve(port)) for port in inner.literals)
                self.walk(self.document.trees[target], inner, span, (*stack, target))
        for child in node.children:
            self.walk(child, scope, span, stack)
        if span is not loops:
            span[-1][1] = self.position  # type: ignore[index]

    def check_types(self, node: TreeNode, scope: _Scope) -> None:
        """BT.CPP types an entry after the first typed port that uses it, and refuses a second of another type."""
        kind = kind_of(node.type)
        for name, port in kind.ports.items() if kind is not None and not kind.subtree else ():
            key = bare_key(node.ports.get(name) or "")
            if key is None or port.type == ANY:
                continue
            resolved = scope.resolve(key)
            known = self.types.get(resolved)
            if not compatible(known, port.type):
                self.report(node, type_conflict(key, known, port.type), WRONG_FORMAT)  # type: ignore[arg-type]
            self.types.setdefault(resolved, port.type)

    @staticmethod
    def scripts(node: TreeNode) -> list[Script]:
        found = []
        for port in (*ports_in(node.type, "script"), *PRECONDITIONS, *POSTCONDITIONS):
            if port in node.ports:
                with contextlib.suppress(ScriptError):  # reported by verification
                    found.append(compile_script(node.ports[port]))
        return found

    @staticmethod
    def port_reads(node: TreeNode) -> list[str]:
        keys: list[str] = []
        kind = kind_of(node.type)
        declared = kind.ports if kind is not None else {}
        for port, text in node.ports.items():
            if kind is not None and kind.subtree and port not in PRECONDITIONS:
                continue
            if port in declared and (not declared[port].reads or port in kind.writes_only):  # type: ignore[union-attr]
                continue
            keys += template_keys(text)
        return keys

    @staticmethod
    def port_writes(node: TreeNode) -> list[str]:
        kind = kind_of(node.type)
        if kind is None:
            return []
        keys = [output_key(node.ports[name]) for name, port in kind.ports.items()
                if (port.direction == "output" or name in kind.writes_only) and node.ports.get(name, "").strip()]
        for port in kind.ports_in("query"):  # a query's variables
            keys += [v.lstrip("?") for v in re.findall(r"\?[A-Za-z_][A-Za-z0-9_]*", node.ports.get(port, ""))]
        return keys
