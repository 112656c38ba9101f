"""Parse belief expressions, caching the results: the common shape of a goal or fact (``position(self, ?here)``)
read by hand (:func:`read_flat_goal`), anything else with Lark from ``grammar/beliefs.lark``
(:mod:`~aeroexec.beliefs.grammar_reading`, imported only then: importing Lark is ~50 ms of a command's start)."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from functools import lru_cache
from pathlib import Path
from sys import intern

from aeroexec.beliefs.errors import BeliefSyntaxError, RuleError, RuleProblem, UnknownPredicateError
from aeroexec.beliefs.expression import BUILTIN_PREDICATES, COMPARISON_OPERATORS, Comparison, Conjunction, Goal, Rule
from aeroexec.beliefs.terms import Struct, Var, is_ground

from aeroexec.limits import (
    MAX_LITERALS,
    MAX_NUMBER_LENGTH,
    MAX_TERM_DEPTH,
    InputError,
    line_of_offset,
    nesting_beyond,
    read_text,
)

__all__ = ["check_expression", "check_predicates", "parse_belief",
           "parse_expression", "parse_rules", "parse_term", "read_flat_fact", "read_flat_fact_parts",
           "read_flat_goal", "read_flat_parts",
           "read_rules"]

#: Longest expression accepted; longer text is refused before parsing.
MAX_EXPRESSION_LENGTH = 200_000
#: Longest rules text accepted (a rules file, a catalog's ``rules:``, ``add_rules``); refused before parsing.
MAX_RULES_LENGTH = 10 * MAX_EXPRESSION_LENGTH

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
    from aeroexec.beliefs.grammar_reading import read_rules_text  # Lark: only when rules are read

    return read_rules_text(text, file, first_line)


def read_rules(path: str | Path) -> list[Rule]:
    """The rules and facts of a rules file (``--rules FILE``); raises :class:`RuleError` naming the file and line
    of a mistake (a file that cannot be read, too large, not UTF-8 included)."""
    try:
        text = read_text(path, what="the rules file")
    except InputError as error:
        raise RuleError([RuleProblem(error.message, str(path), error.line)]) from None
    return parse_rules(text, str(path))


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
    flat = read_flat_goal(stripped)  # the common shape, read by hand: no Lark (~50 ms of a command's start-up)
    if flat is not None:
        literals: list = [Goal(flat)]
    else:
        from aeroexec.beliefs.grammar_reading import read_expression

        literals = read_expression(text, stripped)
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


def check_expression(expression: str | Conjunction, predicates: Mapping[str, int]) -> Conjunction:
    """An expression parsed and checked against ``predicates`` (name -> arity; none: nothing is checked), without
    solving: what ``BeliefMemory(predicates=...).check(expression)`` answers, without a memory (a mission's
    expressions are checked before flight without importing the memory and the rules engine)."""
    conjunction = expression if type(expression) is Conjunction else parse_expression(expression)
    check_predicates(conjunction, predicates)
    return conjunction


def check_predicates(conjunction: Conjunction, predicates: Mapping[str, int],
                     answered: Callable[[tuple[str, int]], bool] = lambda signature: False) -> None:
    """Raise :class:`UnknownPredicateError` for the first predicate of ``conjunction`` that ``predicates`` (name ->
    arity; none: nothing is checked) does not declare with its arity, built-in ones and those ``answered`` says are
    known otherwise (computed, derived by rules) aside."""
    if not predicates:
        return
    for name, arity in conjunction.predicates:
        if (name, arity) in BUILTIN_PREDICATES or answered((name, arity)):
            continue
        declared = predicates.get(name)
        if declared is None:
            raise UnknownPredicateError(name, conjunction.text or str(conjunction))
        if declared != arity:
            raise UnknownPredicateError(
                f"{name}/{arity}",
                conjunction.text or str(conjunction),
                f"{name} takes {declared} argument{'s' if declared != 1 else ''}",
            )


#: Values of the pieces the hand reader has read that are not atoms (``?C``, ``2.0``, ``500``), by their text: a
#: belief's text repeats most of its variables and constants, so a piece read before costs one look-up. Atoms are
#: not kept here: ``sys.intern`` is their table already. Each value is immutable (an int, a float, a named variable,
#: interned); ``?`` alone is never kept (each one is a new variable). Small (it stays in the processor's cache
#: while texts of new numbers pass through it), and emptied when full.
_PIECES: dict[str, object] = {}
_MAX_PIECES = 4096


def _read_piece(piece: str):
    """The value of one piece of a flat goal not found in :data:`_PIECES` (a name, a variable, a number), kept there
    (``?`` alone aside); None when it is none of those."""
    if piece[:1] == "?":  # ?[A-Za-z0-9_]*
        if len(piece) == 1:
            return Var(piece)  # each ? is a variable of its own: not kept
        if not ("_" + piece[1:]).isidentifier():
            return None
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
    if len(_PIECES) >= _MAX_PIECES:
        _PIECES.clear()
    _PIECES[piece] = value
    return value


def read_flat_parts(text: str, stored: bool = True) -> tuple[str, tuple] | None:
    """The name and arguments of a goal of the common shape (:func:`read_flat_goal`), without building its term:
    ``("color", ("o500", ?C))``; None for anything else. ``stored=False``: the arguments only look beliefs up
    (a question asked once), so the atoms of a goal without a tuple are not interned (equal text finds them in an
    index all the same; ``sys.intern``'s table is as large as the memory's objects, and its look-up is one more
    cache miss a question)."""
    if not text.isascii():  # quotes, comments, lists: in a piece, which then is not one (None)
        return None
    body = text.strip(_LARK_SPACE)
    if body[-1:] != ")":
        return None
    name, found, inside = body[:-1].partition("(")
    name = name.rstrip(_LARK_SPACE)
    if not found or name == "not" or not name.isidentifier():  # ASCII: [A-Za-z_][A-Za-z0-9_]*, the grammar's NAME
        return None
    if "(" not in inside:  # no tuple: each piece is an argument (_read_pieces, inline: the commonest shape)
        known = _PIECES.get
        args = []
        for piece in inside.split(","):
            piece = piece.strip(_LARK_SPACE)
            if piece.isidentifier():  # an atom: one object however often it is read, found in an index by identity
                args.append(intern(piece) if stored else piece)
                continue
            if piece.isdigit() and len(piece) <= MAX_NUMBER_LENGTH:  # an integer (ASCII digits): int() is as cheap
                args.append(int(piece))  # as a look-up, and a text of new numbers would only churn the table
                continue
            value = known(piece)
            if value is None:
                value = _read_piece(piece)
                if value is None:
                    return None
            args.append(value)
        return intern(name) if stored else name, tuple(args)
    args = []
    rest = inside
    while True:  # pieces up to a tuple, the tuple; until no tuple is left
        head, opened, rest = rest.partition("(")
        if not opened:  # the last pieces
            pieces = _read_pieces(head)
            if pieces is None:
                return None
            args += pieces
            break
        head = head.rstrip(_LARK_SPACE)
        if head:  # pieces before the tuple, the last of them followed by its comma
            if head[-1] != ",":
                return None
            pieces = _read_pieces(head[:-1])
            if pieces is None:
                return None
            args += pieces
        inner, closed, rest = rest.partition(")")
        if not closed or "(" in inner:  # not closed, or nested
            return None
        pieces = _read_pieces(inner)
        if pieces is None:
            return None
        args.append(tuple(pieces))
        rest = rest.lstrip(_LARK_SPACE)
        if not rest:
            break
        if rest[0] != ",":
            return None
        rest = rest[1:]
    return intern(name), tuple(args)


def _read_pieces(text: str) -> list | None:
    """The values of comma-separated pieces (each a name, a variable or a number: :func:`_read_piece`), None if
    one is not."""
    known = _PIECES.get
    values = []
    for piece in text.split(","):
        piece = piece.strip(_LARK_SPACE)
        if piece.isidentifier():
            values.append(intern(piece))
            continue
        value = known(piece)
        if value is None:
            value = _read_piece(piece)
            if value is None:
                return None
        values.append(value)
    return values


def read_flat_goal(text: str) -> Struct | None:
    """A hand reading of the common shape of a goal or fact: ``name(arg, ...)``, each argument a name, a number, a
    variable or a flat tuple of those (``position(o1, (0.5, 2.0, -3))``, ``color(o500, ?C)``). Anything else (strings,
    lists, nested terms, comments, text that is not ASCII, a number the grammar reads otherwise) is None: read it
    with the grammar (Lark), whose result this one equals wherever it gives one (tests check it on the fuzz corpus).
    Lark's per-call overhead is most of what reading a short belief costs; this reads one in a few microseconds."""
    parts = read_flat_parts(text)
    return None if parts is None else Struct(*parts)


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
    parts = read_flat_fact_parts(text)
    return None if parts is None else Struct(*parts)


def read_flat_fact_parts(text: str) -> tuple[str, tuple] | None:
    """The name and arguments of a ground fact of the common shape (:func:`read_flat_fact`), None otherwise."""
    return None if "?" in text else read_flat_parts(text)


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
