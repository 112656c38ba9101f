"""BehaviorTree.CPP v4's script language on a tree's blackboard, parsed with Lark from ``grammar/script.lark``.

``compile_script(text)`` returns a :class:`Script`; ``script.run(blackboard, beliefs)`` runs its statements and
returns the last one's value. Values are as in BT.CPP: numbers (integer literals stay integers, arithmetic gives
floats), strings; ``true``/``false`` are 1.0/0.0 (BT.CPP 4.10); comparisons and ``&& || !`` give 1.0/0.0; ``==``
between numbers allows a float epsilon. Types are BT.CPP's: arithmetic needs numbers (``'3' + 1`` is refused), a
comparison reads a string against a number as a number, an entry keeps its type (``n := 1; n = 'abc'`` is refused),
a condition is a double or the integers 0 and 1. ``:=`` creates a key, ``=`` needs an existing one.
``belief("...")`` (aeroexec's one extension, not portable) is 1.0 when the belief expression holds. What fails
raises :class:`ScriptError` with BT.CPP's message.
"""

from __future__ import annotations

import functools
import math
import operator
import sys
from collections.abc import Callable, MutableMapping

__all__ = ["Script", "ScriptCompiler", "ScriptError", "compile_script", "text_of", "truth"]

from aeroexec.trees import conversions

from aeroexec.limits import MAX_NESTING

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from lark import Lark, Transformer, Tree

    Evaluator = Callable[[MutableMapping[str, Any], Callable[[str], bool] | None], Any]

_EPSILON = sys.float_info.epsilon * 2 ** 29  # float's epsilon, as BT.CPP compares doubles
Value = int | float | str


class ScriptError(ValueError):
    """A script that does not parse, or fails while it runs (the message names the script)."""


@functools.cache
def _parser() -> Lark:
    """The script grammar's parser; Lark is imported here, when a first script is compiled, not with this module
    (importing Lark is ~50 ms of the start-up of a command whose mission has no script)."""
    from aeroexec.grammar import lalr_parser

    return lalr_parser("script.lark")


@functools.cache
def _compiler() -> type[Transformer]:
    """:class:`ScriptCompiler` as the Lark transformer it is (made when a first script is compiled)."""
    from lark import Transformer

    return type("ScriptCompiler", (ScriptCompiler, Transformer), {"__module__": __name__})


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float)


def _string_to_double(value: str) -> float:
    """BT.CPP's ``StringToDouble``: ``true``/``false`` are 1 and 0, else the number the text starts with."""
    if value == "true":
        return 1.0
    if value == "false":
        return 0.0
    try:
        return conversions.convert(value, conversions.DOUBLE)
    except conversions.ConversionError:
        raise ScriptError("Any failed string to number conversion") from None


def truth(value: Any) -> bool:
    """A script's value as a condition (BT.CPP's ``cast<bool>``): a double is true when not zero, an integer must be
    0 or 1; a negative number and text are refused."""
    if _is_number(value) and value < 0:
        raise ScriptError("Value is negative and can't be converted to unsigned")
    if isinstance(value, float):
        return value != 0
    if isinstance(value, int):
        if value not in (0, 1):
            raise ScriptError("Implicit casting to bool is not allowed")
        return bool(value)
    raise ScriptError(f"[Any::convert]: no known safe conversion between [{_kind(value)}] and [bool]")


def _holds(value: Any) -> bool:
    """The condition of ``a ? b : c``: a number not zero (text is read as a number)."""
    if isinstance(value, str):
        try:
            return conversions.convert(value, conversions.DOUBLE) != 0
        except conversions.ConversionError:
            raise ScriptError("Any failed string to number conversion") from None
    return bool(value)


def _kind(value: Any) -> str:
    return "std::string" if isinstance(value, str) else "double" if isinstance(value, float) else type(value).__name__


def _compare(op: str, left: Any, right: Any) -> bool:
    if _is_number(left) and _is_number(right):
        a, b = float(left), float(right)
    elif isinstance(left, str) and isinstance(right, str):
        a, b = left, right
    elif isinstance(left, str) and _is_number(right):
        a, b = _string_to_double(left), float(right)
    elif _is_number(left) and isinstance(right, str):
        a, b = float(left), _string_to_double(right)
    else:
        raise ScriptError(f"Can't mix different types in Comparison. Left operand [{_kind(left)}] right operand "
                          f"[{_kind(right)}]")
    if op in ("==", "!=") and isinstance(a, float):
        return (abs(a - b) <= _EPSILON) == (op == "==")  # type: ignore[operator]
    return {"==": operator.eq, "!=": operator.ne, "<": operator.lt, ">": operator.gt, "<=": operator.le,
            ">=": operator.ge}[op](a, b)


def _binary(op: str, left: Any, right: Any) -> Any:
    if _is_number(left) and _is_number(right):
        if op in ("&&", "||"):
            try:
                a, b = truth(left), truth(right)
            except ScriptError:
                raise ScriptError("Logic operators are not allowed if one of the operands is not castable to "
                                  "bool") from None
            return float(a and b) if op == "&&" else float(a or b)
        if op in ("&", "|", "^"):
            if not (math.isfinite(left) and math.isfinite(right)) or left != int(left) or right != int(right):
                raise ScriptError("Binary operators are not allowed if one of the operands is not an integer")
            return float({"&": operator.and_, "|": operator.or_, "^": operator.xor}[op](int(left), int(right)))
        a, b = float(left), float(right)
        if op == "/" and b == 0:
            return math.copysign(math.inf, a) * math.copysign(1.0, b) if a else math.nan
        if op in ("+", "-", "*", "/"):
            return {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}[op](a, b)
    elif op == "+" and isinstance(left, str) and isinstance(right, str):
        return left + right
    elif op == ".." and (isinstance(left, str) or isinstance(right, str)) and all(
            isinstance(v, str) or _is_number(v) for v in (left, right)):
        return text_of(left) + text_of(right)
    raise ScriptError("Operation not permitted")


def _unary(op: str, value: Any) -> float:
    if isinstance(value, str):
        raise ScriptError("Invalid operator for std::string")
    if not _is_number(value):
        raise ScriptError("ExprUnaryArithmetic: undefined")
    if op == "~" and not -2.0 ** 63 <= value <= 2.0 ** 63 - 1:  # nan fails both tests
        raise ScriptError("Number out of range for bitwise operation")
    return float(-value) if op == "-" else float(not value) if op == "!" else float(~int(value))


def _assigned(name: str, op: str, old: Any, value: Any, kind: str | None) -> Any:
    """What an assignment writes to an entry holding ``old`` (None: none yet) of type ``kind`` (a port's, else None),
    as BT.CPP's ``ExprAssignment``: an entry keeps its type."""
    if op in (":=", "="):
        if old is None and kind is None:
            return value
        if isinstance(value, str) and not isinstance(old, str):
            if kind is not None:
                return value  # the blackboard converts text written to a typed entry
            if _is_number(old):
                return _string_to_double(value)
            raise ScriptError(f"Error assigning a value to entry [{name}]: the right operand is a string, can't "
                              f"convert to {_kind(old)}")
        return _copied(name, value, old)
    if old is None:
        raise ScriptError(f"The left operand of the operator [{op}] is not initialized")
    if _is_number(value):
        if not _is_number(old):
            raise ScriptError("This Assignment operator can't be used with a non-numeric type")
        return _copied(name, _binary(op[0], old, value), old)
    if isinstance(value, str) and op == "+=":
        return _copied(name, text_of(old) + value, old)
    raise ScriptError("Operator not supported for strings")


def _copied(name: str, value: Any, old: Any) -> Any:
    """BT.CPP's ``Any::copyInto``: a value written over ``old`` takes its type (a number is cast when nothing is lost;
    text stays text)."""
    if old is None or type(value) is type(old) or (isinstance(value, str) and isinstance(old, str)):
        return value
    if _is_number(value) and _is_number(old):
        if isinstance(old, float):
            return float(value)
        if value != int(value) or not math.isfinite(value):
            raise ScriptError(f"Error assigning a value to entry [{name}] with type [int]: the right operand has "
                              f"type [double] and can't be converted to [int]")
        return int(value)
    raise ScriptError(f"Error assigning a value to entry [{name}] with type [{_kind(old)}]: the right operand has "
                      f"type [{_kind(value)}] and can't be converted to [{_kind(old)}]")


text_of = conversions.text_of


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


class ScriptCompiler:
    """The parse tree of a script as evaluators (``(blackboard, beliefs) -> value``), one method per rule it
    builds; ``start`` gives the list of statements. A Lark ``Transformer`` when used (:func:`_compiler`)."""

    def start(self, statements: list[Evaluator | None]) -> list[Evaluator]:
        return [s for s in statements if s is not None]

    def assignment(self, children: list) -> Evaluator:
        written, op, value = str(children[0]), str(children[1]), children[2]

        def assign(board, beliefs):
            board, name = _scope(board, written)
            has_entry = getattr(board, "has_entry", board.__contains__)  # made by a port that uses it, or written
            if op != ":=" and not has_entry(name):
                raise ScriptError(f"The blackboard entry [{name}] doesn't exist, yet. If you want to create a new "
                                  "one, use the operator [:=] instead of [=]")
            created = op == ":=" and not has_entry(name)
            result = value(board, beliefs)
            type_of = getattr(board, "type_of", None)
            result = _assigned(name, op, board.get(name), result, type_of(name) if type_of is not None else None)
            try:
                board[name] = result
            except conversions.ConversionError as error:
                raise ScriptError(f"Error assigning a value to entry [{name}]: {error}") from None
            if created and hasattr(board, "made_by_script"):
                board.made_by_script(name)
            return board[name]

        return assign

    def choice(self, children: list) -> Evaluator:
        test, then, otherwise = children
        return lambda board, beliefs: (then if _holds(test(board, beliefs)) else otherwise)(board, beliefs)

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

        return lambda board, beliefs: _unary(op, operand(board, beliefs))

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
        return _constant(1.0)  # BT.CPP 4.10's Boolean literal is a double (4.8.2's was an integer)

    def false(self, children: list) -> Evaluator:
        return _constant(0.0)

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
        from lark.exceptions import LarkError

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
        self.statements: list[Evaluator] = _compiler()().transform(tree)
        self.portable = "belief" not in {t.data for t in tree.iter_subtrees()}
        #: the blackboard keys the script assigns, and those it reads (``x += 1`` reads x)
        self.writes = [str(t.children[0]) for t in tree.iter_subtrees() if t.data == "assignment"]
        self.reads = [str(t.children[0]) for t in tree.iter_subtrees()
                      if t.data == "name" or (t.data == "assignment" and str(t.children[1]) not in (":=", "="))]

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
    from lark import Tree

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
