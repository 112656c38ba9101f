"""Constant values in a mission's source: literals, and names bound once to them, followed to where they are used.

``endPoint = [8, 8, 0.7]`` then ``executeBehavior('GO_TO_POINT', coordinates=endPoint)``: the checker judges the
destination as if it were written inline. A name is a constant when it is bound exactly once in its scope (the
module, or a function's body, at the top level of it, not in a branch or loop), by a plain assignment of a
constant: a literal (numbers, text, booleans, ``None``), a list or tuple of constants, ``-x`` of a number, an
item of a constant list (``PATH[0]``), or another constant name. Anything else — arithmetic, a call, a
parameter, a loop variable, a name assigned twice or declared ``global`` elsewhere — is left to the run.
"""

from __future__ import annotations

import ast

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

NOT_CONSTANT: Any = object()
_MAX_ITEMS = 10_000  # a constant list longer than this is left to the run
_SCOPES = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)


class Unknown:
    """A value the check cannot know (not a constant): never judged."""

    def __repr__(self) -> str:
        return "<not a constant>"


def _bound_names(target: ast.AST) -> list[str]:
    return [n.id for n in ast.walk(target) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store | ast.Del)]


class Constants:
    """The constants of one parsed program; :meth:`value` of any expression in it."""

    def __init__(self, tree: ast.Module) -> None:
        self.nodes: list[ast.AST] = []  # every node of the program, each before its children (one walk for all)
        self.parents: dict[int, ast.AST] = {}  # id(node) -> the node it is in
        self.scope_of: dict[int, ast.AST] = {}  # id(node) -> its innermost function (or the module)
        self._bindings: dict[tuple[int, str], int] = {}  # (scope, name) -> how many times it is bound
        self._assigned: dict[tuple[int, str], ast.expr] = {}  # (scope, name) -> value, top-level Assign only
        self._globals: set[str] = set()  # names some function declares global or nonlocal
        self._parents: dict[int, ast.AST] = {}
        self._walk(tree, tree)
        self._resolving: set[tuple[int, str]] = set()
        self._cache: dict[tuple[int, str], Any] = {}

    def _walk(self, node: ast.AST, scope: ast.AST) -> None:
        stack = [(node, scope)]
        while stack:
            current, scope = stack.pop()
            self.nodes.append(current)
            self.scope_of[id(current)] = scope
            inner = current if isinstance(current, _SCOPES) and current is not scope else scope
            if inner is not scope:
                self._bind(scope, current.name) if not isinstance(current, ast.Lambda) else None
                self._parents[id(current)] = scope
                arguments = getattr(current, "args", None)
                if isinstance(arguments, ast.arguments):
                    for argument in (*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs,
                                     arguments.vararg, arguments.kwarg):
                        if argument is not None:
                            self._bind(inner, argument.arg)
            self._bindings_of(current, inner)
            if isinstance(current, ast.Module | ast.FunctionDef | ast.AsyncFunctionDef):
                for statement in current.body:
                    self._top_level(statement, current)
            for child in ast.iter_child_nodes(current):
                self.parents[id(child)] = current
                stack.append((child, inner))

    def _bind(self, scope: ast.AST, name: str) -> None:
        key = (id(scope), name)
        self._bindings[key] = self._bindings.get(key, 0) + 1

    def _bindings_of(self, node: ast.AST, scope: ast.AST) -> None:
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store | ast.Del):
            self._bind(scope, node.id)
        elif isinstance(node, ast.Global | ast.Nonlocal):
            self._globals.update(node.names)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            for alias in node.names:
                self._bind(scope, (alias.asname or alias.name).split(".")[0])
        elif isinstance(node, ast.ExceptHandler | ast.MatchAs | ast.MatchStar) and node.name:
            self._bind(scope, node.name)

    def _top_level(self, statement: ast.stmt, scope: ast.AST) -> None:
        """A plain assignment at the top of a scope's body (or, in the module, of an ``if`` there)."""
        if isinstance(statement, ast.Assign) and len(statement.targets) == 1 and \
                isinstance(statement.targets[0], ast.Name):
            self._assigned.setdefault((id(scope), statement.targets[0].id), statement.value)
        elif isinstance(statement, ast.AnnAssign) and isinstance(statement.target, ast.Name) and statement.value:
            self._assigned.setdefault((id(scope), statement.target.id), statement.value)
        elif isinstance(statement, ast.If) and isinstance(scope, ast.Module):
            for inner in (*statement.body, *statement.orelse):
                self._top_level(inner, scope)

    # -- values -----------------------------------------------------------------------------------------
    def value(self, node: ast.AST) -> Any:
        """The constant ``node`` stands for (lists as tuples), or :data:`NOT_CONSTANT`."""
        if isinstance(node, ast.Constant):
            return NOT_CONSTANT if isinstance(node.value, bytes) or node.value is Ellipsis else node.value
        if isinstance(node, ast.Name):
            return self._name(node)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            operand = self.value(node.operand)
            if not _number(operand):
                return NOT_CONSTANT
            return -operand if isinstance(node.op, ast.USub) else operand
        if isinstance(node, ast.List | ast.Tuple):
            if len(node.elts) > _MAX_ITEMS:
                return NOT_CONSTANT
            items = [self.value(e) for e in node.elts]
            return NOT_CONSTANT if any(i is NOT_CONSTANT for i in items) else tuple(items)
        if isinstance(node, ast.Subscript):
            base, index = self.value(node.value), self.value(node.slice)
            if isinstance(base, tuple) and isinstance(index, int) and not isinstance(index, bool) \
                    and -len(base) <= index < len(base):
                return base[index]
        return NOT_CONSTANT

    def _name(self, node: ast.Name) -> Any:
        if node.id in self._globals:
            return NOT_CONSTANT
        scope = self.scope_of.get(id(node))
        own = scope
        while scope is not None:
            key = (id(scope), node.id)
            if key in self._bindings and (scope is own or not isinstance(scope, ast.ClassDef)):
                return self._constant(key)  # a method does not see its class's names, as in Python
            scope = self._parents.get(id(scope))
        return NOT_CONSTANT

    def _constant(self, key: tuple[int, str]) -> Any:
        if key in self._cache:
            return self._cache[key]
        if self._bindings.get(key) != 1 or key not in self._assigned or key in self._resolving:
            return NOT_CONSTANT
        self._resolving.add(key)
        try:
            value = self._cache[key] = self.value(self._assigned[key])
        finally:
            self._resolving.discard(key)
        return value


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


__all__ = ["NOT_CONSTANT", "Constants", "Unknown"]
