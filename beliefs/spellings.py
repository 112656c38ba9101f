"""Value spellings: the atoms a predicate's last argument takes, matched without regard to case.

A catalog may declare the values an updater writes (``battery_level``: low,
medium, high); a belief or expression that spells one of them in another case
(Aerostack's ``battery_level(self, LOW)``) is read as the declared spelling.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from aeroexec.beliefs.expression import Conjunction, Goal, Literal, Negation
from aeroexec.beliefs.terms import Struct

Spellings = Mapping[str, Mapping[str, str]]  # predicate -> lower-case value -> declared spelling


def spelling_table(values: Iterable[str]) -> dict[str, str]:
    """Lower-case value -> the declared spelling."""
    return {str(v).lower(): str(v) for v in values}


def respell_term(term: Struct, spellings: Spellings) -> Struct:
    """``term`` with its last argument in the declared spelling, when it is one of its predicate's values."""
    table = spellings.get(term.name)
    if not table or not term.args:
        return term
    last = term.args[-1]
    if type(last) is not str:
        return term
    declared = table.get(last.lower())
    if declared is None or declared == last:
        return term
    return Struct(term.name, (*term.args[:-1], declared))


def respell(conjunction: Conjunction, spellings: Spellings) -> Conjunction:
    """A conjunction whose goals use the declared spellings (the same object when nothing changes)."""
    if not spellings:
        return conjunction
    literals = tuple(_literal(lit, spellings) for lit in conjunction.literals)
    if all(a is b for a, b in zip(literals, conjunction.literals, strict=True)):
        return conjunction
    return Conjunction(literals, conjunction.text)


def _literal(lit: Literal, spellings: Spellings) -> Literal:
    if type(lit) is Goal:
        term = respell_term(lit.term, spellings)
        return lit if term is lit.term else Goal(term)
    if type(lit) is Negation:
        body = respell(lit.body, spellings)
        return lit if body is lit.body else Negation(body)
    return lit  # a comparison: values compared as written


__all__ = ["Spellings", "respell", "respell_term", "spelling_table"]
