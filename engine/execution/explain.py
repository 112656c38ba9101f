"""Explaining a belief expression that does not hold: which part fails and what the memory holds instead (for a
derived goal, which part of each rule deriving it fails)."""

from __future__ import annotations

from collections.abc import Mapping

from aeroexec.beliefs import BeliefMemory, Conjunction, Goal, Struct, Var, format_term
from aeroexec.beliefs.terms import from_python, substitute

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_SHOWN = 3  # beliefs shown as "what the memory holds"


def explain_failure(memory: BeliefMemory, expression: Conjunction, bindings: Mapping[str, Any] | None = None) -> str:
    """A sentence for the operator: the first part of ``expression`` that fails, with the values known by then.

    Returns an empty string when the expression holds.
    """
    literals = expression.literals
    solution: dict[str, Any] = {}
    for index, literal in enumerate(literals):
        prefix = Conjunction(literals[: index + 1], "")
        found = memory.query(prefix, bindings)
        if found is None:
            return _sentence(memory, expression, literal, solution)
        solution = found
    return ""


def _sentence(memory: BeliefMemory, expression: Conjunction, literal: Any, solution: dict[str, Any]) -> str:
    text = expression.text or str(expression)
    sentence = f"{literal} does not hold" if len(expression.literals) > 1 else "it does not hold"
    known = {name: value for name, value in solution.items() if name in str(literal)}
    if known:
        sentence += " with " + ", ".join(f"{name} = {format_term(value)}" for name, value in sorted(known.items()))
    if isinstance(literal, Goal) and memory.is_derived(literal.term.name, len(literal.term.args)):
        values = {Var(name): from_python(value) for name, value in solution.items()}
        reasons = memory.why_not(substitute(literal.term, values))[1:]  # through the rules that derive it
        if reasons:
            sentence += "; " + "; ".join(reasons)
    elif isinstance(literal, Goal) and not memory.is_computed(literal.term.name, len(literal.term.args)):
        pattern = _pattern(literal.term)
        holds = memory.matching(pattern) if pattern is not None else []
        if holds:
            shown = ", ".join(format_term(b) for b in holds[:_SHOWN]) + (" ..." if len(holds) > _SHOWN else "")
            sentence += f"; the memory holds {shown}"
        elif pattern is not None:
            sentence += f"; the memory holds no {literal.term.name} belief"
    return f"{text}: {sentence}"


def _pattern(term: Any) -> str | None:
    """``predicate(first, ?, ?)``: the same predicate with its first argument kept when ground."""
    if not isinstance(term, Struct):
        return None
    args = list(term.args)
    if not args:
        return format_term(term)
    first = args[0]
    keep = format_term(first) if type(first) is not Var and not isinstance(first, Struct) else "?"
    return f"{term.name}({', '.join([keep] + ['?'] * (len(args) - 1))})"


__all__ = ["explain_failure"]
