"""BehaviorTree.CPP v4's script language on a tree's blackboard, parsed with Lark from ``grammar/script.lark``.

``compile_script(text)`` returns a :class:`Script`; ``script.run(blackboard, beliefs)`` runs its statements and
returns the last one's value. Values are as in BT.CPP: numbers (integer literals stay integers, arithmetic gives
floats), strings; ``true``/``false`` are 1/0; comparisons and ``&& || !`` give 1.0/0.0; ``==`` between numbers
allows a float epsilon. ``:=`` creates a key, ``=`` needs an existing one. ``belief("...")`` (aeroexec's one
extension, not portable) is 1.0 when the belief expression holds.
"""

from __future__ import annotations

import functools
import operator
import sys
from collections.abc import Callable, MutableMapping
from importlib import resources
from typing import Any

__all__ = ["Script", "ScriptCompiler", "ScriptError", "compile_script", "text_of", "truth"]

from lark import Lark, Transformer, Tree
from lark.exceptions import LarkError

from aeroexec.limits import MAX_NESTING

_EPSILON = sys.float_info.epsilon * 2 ** 29  # float's epsilon, as BT.CPP compares doubles
Value = int | float | str
Evaluator = Callable[[MutableMapping[str, Any], Callable[[str], bool] | None], Any]


class ScriptError(ValueError):
    """A script that does not parse, or fails while it runs (the message names the script)."""


@functools.cache
def _parser() -> Lark:
    return Lark(resources.files("aeroexec.grammar").joinpath("script.lark").read_text(), parser="lalr")


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool | int | float):
        return value
    if value == "true":
        return 1
    if value == "false":
        return 0
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ScriptError(f"{what}: {value!r} is not a number") from None


def truth(value: Any) -> bool:
    """A script value as a condition (a non-empty string, a non-zero number)."""
    if isinstance(value, str):
        return value not in ("", "false", "0")
    return bool(value)


def _compare(op: str, left: Any, right: Any) -> bool:
    if isinstance(left, str) and isinstance(right, str):
        a, b = left, right
    else:
        a, b = _number(left, op), _number(right, op)
        if op in ("==", "!="):
            return (abs(a - b) <= _EPSILON) == (op == "==")
    return {"==": operator.eq, "!=": operator.ne, "<": operator.lt, ">": operator.gt, "<=": operator.le,
            ">=": operator.ge}[op](a, b)


def _binary(op: str, left: Any, right: Any) -> Any:
    if op == "..":
        if isinstance(left, str) or isinstance(right, str):
            return _text(left) + _text(right)
        raise ScriptError("Operation not permitted: .. needs a string")
    if op == "+" and isinstance(left, str) and isinstance(right, str):
        return left + right
    if op in ("&&", "||"):
        a, b = truth(left), truth(right)
        return float(a and b) if op == "&&" else float(a or b)
    a, b = _number(left, op), _number(right, op)
    if op in ("&", "|", "^"):
        if a != int(a) or b != int(b):
            raise ScriptError("Binary operators are not allowed if one of the operands is not an integer")
        return float({"&": operator.and_, "|": operator.or_, "^": operator.xor}[op](int(a), int(b)))
    if op == "/" and b == 0:
        return float("inf") if a > 0 else float("-inf") if a < 0 else float("nan")
    return float({"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}[op](a, b))


def _text(value: Any) -> str:
    """A value as text, a float as BT.CPP prints a double (``std::to_string``: six decimals)."""
    if isinstance(value, bool):
        return str(int(value))
    return f"{value:.6f}" if isinstance(value, float) else str(value)


text_of = _text


def _scope(board: MutableMapping[str, Any], name: str) -> tuple[MutableMapping[str, Any], str]:
    """``@key`` is the key of the root blackboard (the main tree's), as in BT.CPP."""
    if not name.startswith("@"):
        return board, name
    while getattr(board, "parent", None) is not None:
        board = board.parent  # type: ignore[attr-defined]
    return board, name[1:]


def _read(written: str) -> Evaluator:
    def read(board, beliefs):
        board, name = _scope(board, written)
        if name not in board:
            raise ScriptError(f"Variable not found: {name}")
        return board[name]

    return read


def _constant(value: Value) -> Evaluator:
    return lambda board, beliefs: value


class ScriptCompiler(Transformer):
    """The parse tree of a script as evaluators (``(blackboard, beliefs) -> value``), one method per rule it
    builds; ``start`` gives the list of statements."""

    def start(self, statements: list[Evaluator | None]) -> list[Evaluator]:
        return [s for s in statements if s is not None]

    def assignment(self, children: list) -> Evaluator:
        written, op, value = str(children[0]), str(children[1]), children[2]

        def assign(board, beliefs):
            board, name = _scope(board, written)
            if op != ":=" and name not in board:
                raise ScriptError(f"The blackboard entry [{name}] doesn't exist, yet. If you want to create a new "
                                  "one, use the operator [:=] instead of [=]")
            result = value(board, beliefs)
            old = board.get(name)
            if op not in (":=", "="):
                if old is None:
                    raise ScriptError(f"The left operand of the operator [{op}] is not initialized")
                result = (str(old) + result if op == "+=" and isinstance(result, str)
                          else _binary(op[0], old, result))
            if isinstance(old, int) and isinstance(result, float) and result.is_integer():
                result = int(result)  # an entry keeps its type, as in BT.CPP
            board[name] = result
            return result

        return assign

    def choice(self, children: list) -> Evaluator:
        test, then, otherwise = children
        return lambda board, beliefs: (then if truth(test(board, beliefs)) else otherwise)(board, beliefs)

    def binary(self, children: list) -> Evaluator:
        left, op, right = children[0], str(children[1]), children[2]
        return lambda board, beliefs: _binary(op, left(board, beliefs), right(board, beliefs))

    def compare(self, children: list) -> Evaluator:
        operands, ops = children[0::2], [str(op) for op in children[1::2]]

        def compare(board, beliefs):
            left = operands[0](board, beliefs)
            for op, operand in zip(ops, operands[1:], strict=True):
                right = operand(board, beliefs)
                if not _compare(op, left, right):
                    return 0.0
                left = right
            return 1.0

        return compare

    def unary(self, children: list) -> Evaluator:
        op, operand = str(children[0]), children[1]

        def unary(board, beliefs):
            value = _number(operand(board, beliefs), op)
            return float(-value) if op == "-" else float(not value) if op == "!" else float(~int(value))

        return unary

    def name(self, children: list) -> Evaluator:
        return _read(str(children[0]))

    def belief(self, children: list) -> Evaluator:
        expression = str(children[0])[1:-1]

        def belief(board, beliefs):
            if beliefs is None:
                raise ScriptError("belief(...) needs the engine's beliefs")
            return float(beliefs(expression))

        return belief

    def true(self, children: list) -> Evaluator:
        return _constant(1)

    def false(self, children: list) -> Evaluator:
        return _constant(0)

    def string(self, children: list) -> Evaluator:
        return _constant(str(children[0])[1:-1])

    def real(self, children: list) -> Evaluator:
        return _constant(float(children[0]))

    def hex(self, children: list) -> Evaluator:
        return _constant(int(str(children[0]), 16))

    def integer(self, children: list) -> Evaluator:
        return _constant(int(children[0]))


class Script:
    """A parsed script: ``run`` it on a blackboard (``beliefs`` answers ``belief("...")``)."""

    def __init__(self, text: str) -> None:
        self.text = text
        try:
            tree = _parser().parse(text)
        except LarkError as error:
            raise ScriptError(f"Error parsing the script [{text}]: {str(error).splitlines()[0]}") from None
        statements = [s for s in tree.children if s is not None]
        if _depth(tree) > MAX_NESTING:
            raise ScriptError(f"Error parsing the script [{_shortened(text)}]: it is nested more than "
                              f"{MAX_NESTING} levels deep")
        if not statements:
            raise ScriptError(f"Empty Script [{text}]")
        self.statements: list[Evaluator] = ScriptCompiler().transform(tree)
        self.portable = "belief" not in {t.data for t in tree.iter_subtrees()}
        #: the blackboard keys the script assigns
        self.writes = [str(t.children[0]) for t in tree.iter_subtrees() if t.data == "assignment"]

    def run(self, blackboard: MutableMapping[str, Any], beliefs: Callable[[str], bool] | None = None) -> Any:
        try:
            result = None
            for statement in self.statements:
                result = statement(blackboard, beliefs)
            return result
        except ScriptError as error:
            raise ScriptError(f"Error in script [{self.text}]: {error}") from None

    def holds(self, blackboard: MutableMapping[str, Any], beliefs: Callable[[str], bool] | None = None) -> bool:
        return truth(self.run(blackboard, beliefs))


def _depth(tree: Tree) -> int:
    """The depth of a parse tree, walked without recursion (a chain of a thousand ``..`` is one long branch)."""
    deepest, pending = 0, [(tree, 1)]
    while pending:
        node, depth = pending.pop()
        deepest = max(deepest, depth)
        pending.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))
    return deepest


def _shortened(text: str, limit: int = 80) -> str:
    return text if len(text) <= limit else text[:limit] + "..."


@functools.lru_cache(maxsize=1024)
def compile_script(text: str) -> Script:
    """The parsed script (cached by text); raises :class:`ScriptError`."""
    return Script(text)
