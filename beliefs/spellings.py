"""Value spellings: the atoms a predicate's last argument takes, matched without regard to case, and aliases.

A catalog may declare the values an updater writes (``battery_level``: low,
medium, high); a belief or expression that spells one of them in another case
(Aerostack's ``battery_level(self, LOW)``) is read as the declared spelling. An
alias stands for several values in expressions: with ``flying: [hovering,
moving]``, ``flight_state(self, FLYING)`` holds when the state is either.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from aeroexec.beliefs.expression import Conjunction, Goal, Literal, Negation
from aeroexec.beliefs.terms import ListTerm, Struct, Var

#: predicate -> lower-case value -> the declared spelling, or the values an alias stands for
Spellings = Mapping[str, Mapping[str, str | tuple[str, ...]]]


def spelling_table(values: Iterable[str], aliases: Mapping[str, Iterable[str]] | None = None
                   ) -> dict[str, str | tuple[str, ...]]:
    """Lower-case value -> the declared spelling; lower-case alias -> the values it stands for."""
    table: dict[str, str | tuple[str, ...]] = {str(v).lower(): str(v) for v in values}
    for alias, meant in (aliases or {}).items():
        table[str(alias).lower()] = tuple(str(table.get(str(m).lower(), m)) for m in meant)
    return table


def respell_term(term: Struct, spellings: Spellings) -> Struct:
    """``term`` with its last argument in the declared spelling, when it is one of its predicate's values."""
    declared = _declared(term, spellings)
    if not isinstance(declared, str) or declared == term.args[-1]:
        return term
    return Struct(term.name, (*term.args[:-1], declared))


def _declared(term: Struct, spellings: Spellings) -> str | tuple[str, ...] | None:
    table = spellings.get(term.name)
    if not table or not term.args or type(term.args[-1]) is not str:
        return None
    return table.get(term.args[-1].lower())


def respell(conjunction: Conjunction, spellings: Spellings) -> Conjunction:
    """A conjunction whose goals use the declared spellings, aliases expanded (the same object when nothing
    changes)."""
    if not spellings:
        return conjunction
    literals: list[Literal] = []
    for lit in conjunction.literals:
        literals.extend(_literal(lit, spellings))
    if len(literals) == len(conjunction.literals) and all(
            a is b for a, b in zip(literals, conjunction.literals, strict=True)):
        return conjunction
    return Conjunction(tuple(literals), conjunction.text)


def _literal(lit: Literal, spellings: Spellings) -> list[Literal]:
    if type(lit) is Goal:
        declared = _declared(lit.term, spellings)
        if isinstance(declared, tuple):  # an alias: any of its values
            value = Var("?")
            goal = Struct(lit.term.name, (*lit.term.args[:-1], value))
            return [Goal(goal), Goal(Struct("belong", (value, ListTerm(declared))))]
        term = respell_term(lit.term, spellings)
        return [lit if term is lit.term else Goal(term)]
    if type(lit) is Negation:
        body = respell(lit.body, spellings)
        return [lit if body is lit.body else Negation(body)]
    return [lit]  # a comparison: values compared as written


__all__ = ["Spellings", "respell", "respell_term", "spelling_table"]
