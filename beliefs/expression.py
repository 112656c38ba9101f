"""Parsed belief expressions: a conjunction of goals, comparisons and negations."""

from __future__ import annotations

from dataclasses import dataclass, field

from aeroexec.beliefs.terms import Struct, Var, format_term, variables

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Predicates the evaluator answers itself rather than from stored beliefs.
BUILTIN_PREDICATES = {("belong", 2), ("less_than", 2), ("greater_than", 2)}

COMPARISON_OPERATORS = ("<", ">", "<=", ">=", "=", "!=")


@dataclass(frozen=True, slots=True)
class Goal:
    """A predicate to prove: a stored belief, a built-in or a computed predicate."""

    term: Struct

    def __str__(self) -> str:
        return format_term(self.term)


@dataclass(frozen=True, slots=True)
class Comparison:
    """``left op right`` with op one of ``< > <= >= = !=``."""

    op: str
    left: Any
    right: Any

    def __str__(self) -> str:
        return f"{format_term(self.left)} {self.op} {format_term(self.right)}"


@dataclass(frozen=True, slots=True)
class Negation:
    """``not(...)``: negation as failure of a conjunction."""

    body: Conjunction

    def __str__(self) -> str:
        return f"not({self.body})"


Literal = Goal | Comparison | Negation


@dataclass(frozen=True, slots=True)
class Conjunction:
    """Literals joined by commas; true when all hold under one unification."""

    literals: tuple[Literal, ...]
    text: str = field(default="", compare=False)

    def __str__(self) -> str:
        return ", ".join(str(lit) for lit in self.literals)

    @property
    def predicates(self) -> frozenset[tuple[str, int]]:
        """Name and arity of every goal, built-ins excluded, negations included."""
        found: set[tuple[str, int]] = set()
        for lit in self.literals:
            if type(lit) is Goal:
                if lit.term.signature not in BUILTIN_PREDICATES:
                    found.add(lit.term.signature)
            elif type(lit) is Negation:
                found |= lit.body.predicates
        return frozenset(found)

    @property
    def variables(self) -> tuple[Var, ...]:
        """Named variables in order of first appearance (anonymous ones left out)."""
        seen: dict[Var, None] = {}
        for lit in self.literals:
            for v in literal_variables(lit):
                if not v.anonymous:
                    seen.setdefault(v, None)
        return tuple(seen)


@dataclass(frozen=True, slots=True)
class Rule:
    """A Horn clause ``head :- body.``: the head holds for every unification of the body; without a body, a
    fact. ``file`` and ``line`` say where it was written."""

    head: Struct
    body: Conjunction
    file: str = field(default="", compare=False)
    line: int = field(default=0, compare=False)

    def __str__(self) -> str:
        if not self.body.literals:
            return f"{format_term(self.head)}."
        return f"{format_term(self.head)} :- {self.body}."

    @property
    def where(self) -> str:
        """``file:line`` (or what is known of it)."""
        where = self.file or "<rules>"
        return f"{where}:{self.line}" if self.line else where


def literal_variables(lit: Literal) -> list[Var]:
    """Every variable a literal mentions, negated bodies included."""
    if type(lit) is Goal:
        return list(variables(lit.term))
    if type(lit) is Comparison:
        return [*variables(lit.left), *variables(lit.right)]
    out: list[Var] = []
    for inner in lit.body.literals:
        out.extend(literal_variables(inner))
    return out
