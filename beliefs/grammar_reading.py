"""Belief expressions and rules read with Lark from ``grammar/beliefs.lark`` (what the hand reader of
:mod:`~aeroexec.beliefs.parser` does not read): imported only when such a text is read, so a command whose beliefs
are all of the common flat shape never imports Lark."""

from __future__ import annotations

import math
import threading
from functools import lru_cache

from aeroexec.beliefs.errors import BeliefSyntaxError, RuleError, RuleProblem
from aeroexec.beliefs.expression import Comparison, Conjunction, Goal, Negation, Rule
from aeroexec.beliefs.terms import ListTerm, Struct, Var, format_term, unquote
from aeroexec.grammar import lalr_parser
from lark import Lark, Transformer, UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, v_args
from lark.exceptions import UnexpectedToken, VisitError

from aeroexec.limits import MAX_LITERALS, MAX_NUMBER_LENGTH

__all__ = ["read_expression", "read_rules_text"]

_TERMINAL_NAMES = {
    "NAME": "a name",
    "VARIABLE": "a variable",
    "NUMBER": "a number",
    "STRING": "a quoted string",
    "COMPARATOR": "a comparison (< > <= >= = !=)",
    "LPAR": "'('",
    "RPAR": "')'",
    "LSQB": "'['",
    "RSQB": "']'",
    "COMMA": "','",
    "DOT": "'.'",
    "__ANON_0": "':-'",
    "IF": "':-'",
    "$END": "the end of the expression",
}


class _Build(Transformer):
    """Turns parse-tree nodes into terms and literals as the LALR parser reduces them."""

    def start(self, items):
        return [_as_literal(item) for item in items]

    def comparison(self, items):
        left, op, right = items
        return Comparison(str(op), left, right)

    def compound(self, items):
        name, *args = items
        if args == [None]:
            args = []
        if str(name) == "not":
            if not args:
                raise _Invalid("not() needs a belief expression inside")
            return Negation(Conjunction(tuple(_as_literal(a) for a in args)))
        for a in args:
            if type(a) in (Comparison, Negation):
                raise _Invalid(f"{a} can only stand at the top of an expression or inside not()")
        return Struct(str(name), tuple(args))

    def tuple(self, items):
        return tuple(i for i in items if i is not None)

    def list(self, items):
        return ListTerm(i for i in items if i is not None)

    def atom(self, items):
        return str(items[0])

    def number(self, items):
        text = str(items[0])
        if len(text) > MAX_NUMBER_LENGTH:
            raise _Invalid(f"a number of {len(text)} characters is longer than the limit of {MAX_NUMBER_LENGTH}")
        if any(c in text for c in ".eE"):
            value = float(text)
            if not math.isfinite(value):  # the README's limits: a number beyond a float's range is a wrong value
                raise _WrongValue(text)
            return value
        return int(text)

    def string(self, items):
        return unquote(str(items[0]))

    def var(self, items):
        return Var(str(items[0]))


class _Invalid(Exception):
    """Raised inside the transformer for a well-formed parse that is not a valid expression."""


class _WrongValue(_Invalid):
    """A value the grammar reads but no belief holds (``1e400``): the paper's WRONG_VALUE."""

    def __init__(self, value: str) -> None:
        super().__init__(f"the value {value} is not correct (a finite number is expected)")
        self.value = value


def _as_literal(item):
    if type(item) in (Comparison, Negation):
        return item
    if type(item) is Struct:
        return Goal(item)
    if type(item) is str:  # a proposition such as `hovering`
        return Goal(Struct(item, ()))
    raise _Invalid(f"{format_term(item)} is not a predicate")


class _BuildRules(_Build):
    """Turns a rules text's parse tree into :class:`Rule` records with their lines (facts: rules without a body)."""

    def __init__(self, file: str, first_line: int) -> None:
        super().__init__()
        self.file, self.offset = file, first_line - 1

    def program(self, items):
        return items

    @v_args(meta=True)
    def rule(self, meta, items):
        head, *body = items
        literals = tuple(_as_literal(b) for b in body)
        if len(literals) > MAX_LITERALS:
            raise _Invalid(f"{len(literals)} literals is more than the limit of {MAX_LITERALS} in one rule")
        return Rule(_head(head), Conjunction(literals), self.file, meta.line + self.offset)

    @v_args(meta=True)
    def fact(self, meta, items):
        return Rule(_head(items[0]), Conjunction(()), self.file, meta.line + self.offset)


def _head(item) -> Struct:
    if type(item) is str:
        return Struct(item, ())
    if type(item) is not Struct:
        raise _Invalid(f"the head of a rule is a predicate such as safe_zone(?Z), not {item}")
    return item


@lru_cache(maxsize=1)
def _rules_parser() -> Lark:
    return lalr_parser("beliefs.lark", start="program", propagate_positions=True, maybe_placeholders=True)


@lru_cache(maxsize=1)
def _parser() -> tuple[Lark, threading.Lock]:
    parser = lalr_parser("beliefs.lark", transformer=_Build(), maybe_placeholders=True)
    return parser, threading.Lock()


def _describe(expected) -> str:
    names = sorted({_TERMINAL_NAMES.get(t, t) for t in expected})
    if not names:
        return ""
    if len(names) == 1:
        return names[0]
    return ", ".join(names[:-1]) + " or " + names[-1]


def _exact_expected(exc: UnexpectedInput) -> set[str] | None:
    """The terminals the parser would really accept here (LALR's own list over-approximates)."""
    if not isinstance(exc, UnexpectedToken) or exc.interactive_parser is None:
        return None
    try:
        return set(exc.interactive_parser.accepts())
    except Exception:  # accepts() replays the parser; any failure just means "no better list"
        return None


def _syntax_error(text: str, exc: UnexpectedInput) -> BeliefSyntaxError:
    column = getattr(exc, "column", None)
    if isinstance(exc, UnexpectedEOF) or (
        isinstance(exc, UnexpectedToken) and exc.token.type == "$END"
    ):
        detail = "the expression ends too early"
    elif isinstance(exc, UnexpectedToken):
        detail = f"unexpected {str(exc.token)!r} at column {column}"
    elif isinstance(exc, UnexpectedCharacters):
        detail = f"unexpected {text[exc.pos_in_stream]!r} at column {column}"
    else:
        detail = f"at column {column}"
    expected = _exact_expected(exc) or getattr(exc, "expected", None) or getattr(exc, "allowed", None)
    if expected:
        detail += f"; expected {_describe(expected)}"
    return BeliefSyntaxError(text, detail, column)


def read_expression(text: str, stripped: str) -> list:
    """The literals of the expression ``stripped`` (``text`` without its surrounding space), read with the
    grammar; raises :class:`BeliefSyntaxError` naming ``text``."""
    parser, lock = _parser()
    try:
        with lock:  # a Lark parser with an inline transformer is not re-entrant
            literals = parser.parse(stripped)
    except UnexpectedInput as exc:
        raise _syntax_error(text, exc) from None
    except VisitError as exc:
        detail = str(exc.orig_exc) if isinstance(exc.orig_exc, _Invalid) else "not a term"
        raise BeliefSyntaxError(text, detail) from None
    except _Invalid as exc:
        raise BeliefSyntaxError(text, str(exc)) from None
    except RecursionError:
        raise BeliefSyntaxError(text, "the expression is nested too deeply") from None
    return literals


def read_rules_text(text: str, file: str, first_line: int) -> list[Rule]:
    """The rules and facts of ``text`` (checked for size and depth by the caller); raises :class:`RuleError`."""
    def refused(message: str, line: int = 0, column: int | None = None) -> RuleError:
        return RuleError([RuleProblem(message, file, line + first_line - 1 if line else 0, column)])

    try:
        tree = _rules_parser().parse(text)
        return _BuildRules(file, first_line).transform(tree)
    except UnexpectedInput as exc:
        detail = _syntax_error(text, exc).detail.replace("the expression ends", "the rules end")
        clause = _clause_at(text, getattr(exc, "pos_in_stream", None))
        raise refused(f"The format of the rule {clause} is not correct ({detail})", exc.line, exc.column) from None
    except VisitError as exc:
        detail = str(exc.orig_exc) if isinstance(exc.orig_exc, _Invalid) else "not a term"
        meta = getattr(exc.obj, "meta", None)
        line = getattr(meta, "line", 0) if meta is not None and not getattr(meta, "empty", True) else 0
        if isinstance(exc.orig_exc, _WrongValue):
            clause = _clause_at(text, getattr(meta, "start_pos", None))
            raise refused(f"The value {exc.orig_exc.value} of {clause} is not correct (a finite number is expected)",
                          line) from None
        raise refused(f"The format of the rule is not correct ({detail})", line) from None
    except RecursionError:
        raise refused("the rules are nested too deeply") from None


def _clause_at(text: str, offset: int | None) -> str:
    """The clause around ``offset`` (from the previous full stop to the next), shortened for a message."""
    if offset is None:
        offset = len(text)
    start = max(text.rfind(".\n", 0, offset), text.rfind(". ", 0, offset)) + 1
    end = text.find(".", offset)
    clause = " ".join(text[start: end + 1 if end >= 0 else len(text)].split())
    return clause if len(clause) <= 120 else clause[:117] + "..."
