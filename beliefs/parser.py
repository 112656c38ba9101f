"""Parse belief expressions with Lark from ``grammar/beliefs.lark``, caching the results."""

from __future__ import annotations

import math
import re
import threading
from functools import lru_cache
from pathlib import Path
from sys import intern

from aeroexec.beliefs.errors import BeliefSyntaxError, RuleError, RuleProblem
from aeroexec.beliefs.expression import COMPARISON_OPERATORS, Comparison, Conjunction, Goal, Negation, Rule
from aeroexec.beliefs.terms import ListTerm, Struct, Var, format_term, is_ground, unquote
from aeroexec.grammar import lalr_parser
from lark import Lark, Transformer, UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, v_args
from lark.exceptions import UnexpectedToken, VisitError

from aeroexec.limits import (
    MAX_LITERALS,
    MAX_NUMBER_LENGTH,
    MAX_TERM_DEPTH,
    InputError,
    line_of_offset,
    nesting_beyond,
    read_text,
)

__all__ = ["parse_belief", "parse_expression", "parse_rules", "parse_term", "read_flat_fact", "read_flat_goal",
           "read_rules"]

#: Longest expression accepted; longer text is refused before parsing.
MAX_EXPRESSION_LENGTH = 200_000
#: Longest rules text accepted (a rules file, a catalog's ``rules:``, ``add_rules``); refused before parsing.
MAX_RULES_LENGTH = 10 * MAX_EXPRESSION_LENGTH

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


def parse_rules(text: str, file: str = "", first_line: int = 1) -> list[Rule]:
    """Parse rules and facts (``head :- body.``, ``fact.``); raises :class:`RuleError` with the line of a mistake.

    ``first_line`` is the line ``text`` starts at in ``file`` (rules inside a catalog).
    """
    def refused(message: str, line: int = 0, column: int | None = None) -> RuleError:
        return RuleError([RuleProblem(message, file, line + first_line - 1 if line else 0, column)])

    if not isinstance(text, str):
        raise refused("rules are text")
    if len(text) > MAX_RULES_LENGTH:
        raise refused(f"the rules are {len(text):,} characters, more than the limit of {MAX_RULES_LENGTH:,}")
    deep = nesting_beyond(text, MAX_TERM_DEPTH)
    if deep is not None:
        line = line_of_offset(text, deep)
        raise refused(f"the rule is nested more than {MAX_TERM_DEPTH} levels deep", line,
                      deep - text.rfind("\n", 0, deep))
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


def read_rules(path: str | Path) -> list[Rule]:
    """The rules and facts of a rules file (``--rules FILE``); raises :class:`RuleError` naming the file and line
    of a mistake (a file that cannot be read, too large, not UTF-8 included)."""
    try:
        text = read_text(path, what="the rules file")
    except InputError as error:
        raise RuleError([RuleProblem(error.message, str(path), error.line)]) from None
    return parse_rules(text, str(path))


def _clause_at(text: str, offset: int | None) -> str:
    """The clause around ``offset`` (from the previous full stop to the next), shortened for a message."""
    if offset is None:
        offset = len(text)
    start = max(text.rfind(".\n", 0, offset), text.rfind(". ", 0, offset)) + 1
    end = text.find(".", offset)
    clause = " ".join(text[start: end + 1 if end >= 0 else len(text)].split())
    return clause if len(clause) <= 120 else clause[:117] + "..."


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


@lru_cache(maxsize=8192)
def parse_expression(text: str) -> Conjunction:
    """Parse a belief expression (a conjunction); raises :class:`BeliefSyntaxError`.

    Results are cached: parsing the same text again costs a dictionary look-up.
    """
    if not isinstance(text, str):
        raise BeliefSyntaxError(repr(text), "a belief expression is text")
    stripped = text.strip()
    if not stripped:
        raise BeliefSyntaxError(text, "the expression is empty")
    if len(stripped) > MAX_EXPRESSION_LENGTH:
        raise BeliefSyntaxError(
            text, f"{len(stripped)} characters is longer than {MAX_EXPRESSION_LENGTH}"
        )
    deep = nesting_beyond(stripped, MAX_TERM_DEPTH)
    if deep is not None:
        column = len(text) - len(text.lstrip()) + deep + 1
        raise BeliefSyntaxError(text, f"nested more than {MAX_TERM_DEPTH} levels deep at column {column}", column)
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
    if len(literals) > MAX_LITERALS:
        raise BeliefSyntaxError(text, f"{len(literals)} literals is more than the limit of {MAX_LITERALS} "
                                      "in one expression")
    for lit in literals:
        if type(lit) is Comparison and lit.op not in COMPARISON_OPERATORS:
            raise BeliefSyntaxError(text, f"unknown comparison {lit.op}")
    return Conjunction(tuple(literals), text)


_LARK_SPACE = " \t\f\r\n"  # what the grammar ignores between tokens (common.WS); str.strip() takes more
_VARIABLE_TOKEN = re.compile(r"\?[A-Za-z0-9_]*")
_NUMBER_TOKEN = re.compile(r"[+-]?(\d+\.\d+|\.\d+|\d+)([eE][+-]?\d+)?")
_INFINITE = (math.inf, -math.inf)
_SIGNS = ("+", "-")


def read_flat_goal(text: str) -> Struct | None:
    """A hand reading of the common shape of a goal or fact: ``name(arg, ...)``, each argument a name, a number, a
    variable or a flat tuple of those (``position(o1, (0.5, 2.0, -3))``, ``color(o500, ?C)``). Anything else (strings,
    lists, nested terms, comments, text that is not ASCII, a number the grammar reads otherwise) is None: read it
    with the grammar (Lark), whose result this one equals wherever it gives one (tests check it on the fuzz corpus).
    Lark's per-call overhead is most of what reading a short belief costs; this reads one in a few microseconds."""
    if not text.isascii() or '"' in text or "'" in text or "%" in text or "[" in text:
        return None
    body = text.strip(_LARK_SPACE)
    if body[-1:] != ")":
        return None
    name, found, inside = body[:-1].partition("(")
    name = name.rstrip(_LARK_SPACE)
    if not found or name == "not" or not name.isidentifier():  # ASCII: [A-Za-z_][A-Za-z0-9_]*, the grammar's NAME
        return None
    args: list = []
    group: list | None = None  # the elements of the tuple being read
    for piece in inside.split(","):
        piece = piece.strip(_LARK_SPACE)
        closes = False
        if piece[:1] == "(":
            if group is not None:
                return None
            group = []
            piece = piece[1:].lstrip(_LARK_SPACE)
        if piece[-1:] == ")":
            if group is None:
                return None
            closes = True
            piece = piece[:-1].rstrip(_LARK_SPACE)
        if piece.isidentifier():
            value = intern(piece)  # an atom: one object however often it is read, found in an index by identity
        elif piece[:1] == "?" and (len(piece) == 1 or ("_" + piece[1:]).isidentifier()):  # ?[A-Za-z0-9_]*
            value = Var(piece)
        else:
            core = piece[1:] if piece[:1] in _SIGNS else piece
            if core.isdigit():  # ASCII digits (the text is ASCII): an integer
                if len(piece) > MAX_NUMBER_LENGTH:
                    return None
                value = int(piece)
            elif core[-1:] != "." and core.replace(".", "", 1).isdigit():  # 0.5, .5: digits with one point inside
                if len(piece) > MAX_NUMBER_LENGTH:
                    return None
                value = float(piece)
            else:
                value = _flat_value(piece)
                if value is None:
                    return None
        if group is None:
            args.append(value)
        else:
            group.append(value)
            if closes:
                args.append(tuple(group))
                group = None
    if group is not None:
        return None
    return Struct(intern(name), tuple(args))


def _flat_value(piece: str):
    """A number or a variable written alone (None for anything else)."""
    if piece[:1] == "?":
        return Var(piece) if _VARIABLE_TOKEN.fullmatch(piece) is not None else None
    if not piece or len(piece) > MAX_NUMBER_LENGTH or _NUMBER_TOKEN.fullmatch(piece) is None:
        return None
    if "." in piece or "e" in piece or "E" in piece:
        number = float(piece)
        return None if number in _INFINITE else number
    return int(piece)


def read_flat_fact(text: str) -> Struct | None:
    """A ground fact of the common shape read by hand (:func:`read_flat_goal`), None for anything else."""
    goal = read_flat_goal(text)
    if goal is None or "?" in text:
        return None
    return goal


_read_flat = read_flat_fact  # its name in the tests that hold it to the grammar


def parse_belief(text: str) -> Struct:
    """Parse one ground belief such as ``charge(battery, 80)``."""
    if isinstance(text, str) and len(text) < 1000:
        flat = read_flat_fact(text)
        if flat is not None:
            return flat
    expr = parse_expression(text)
    if len(expr.literals) != 1 or type(expr.literals[0]) is not Goal:
        raise BeliefSyntaxError(text, "a belief is a single predicate such as charge(battery, 80)")
    belief = expr.literals[0].term
    if not is_ground(belief):
        raise BeliefSyntaxError(text, "a belief cannot hold variables")
    return belief


def parse_term(text: str):
    """Parse a single term (a value), such as ``(1.0, 2.5, -3)`` or ``[a, b]``."""
    expr = parse_expression(f"value({text})")
    goal = expr.literals[0]
    if len(expr.literals) != 1 or type(goal) is not Goal or len(goal.term.args) != 1:
        raise BeliefSyntaxError(text, "expected a single value")
    return goal.term.args[0]
