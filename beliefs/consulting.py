"""Consulting the belief memory: a belief expression read (parsed, its predicates checked against the vocabulary),
compiled once into a query plan kept per expression, and answered, from its standing answer while the relations it
reads stand.

:class:`Consulting` is the part of :class:`~aeroexec.beliefs.memory.BeliefMemory` that turns questions into
answers; the memory's public methods (``query``, ``holds``, ``add`` ...) call it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from aeroexec.beliefs.errors import BeliefSyntaxError, UnknownPredicateError
from aeroexec.beliefs.expression import BUILTIN_PREDICATES, Conjunction, Goal
from aeroexec.beliefs.parser import parse_belief, parse_expression
from aeroexec.beliefs.query import CompiledQuery
from aeroexec.beliefs.spellings import respell
from aeroexec.beliefs.terms import Struct, Var, format_term, from_python

Expression = str | Conjunction | Struct


class Consulting:
    """How a belief memory is consulted (mixed into :class:`~aeroexec.beliefs.memory.BeliefMemory`, which holds the
    state below and ``_expire_due``, ``_is_exclusive``)."""

    _relations: Any
    _rulebook: Any
    _vocabulary: dict[str, int]
    _spellings: dict
    _computed: dict
    _answered: dict
    _queries: dict
    _heap: list
    standing_answers: bool

    def _answer(self, expression: Expression, bindings: Mapping[str, Any] | None) -> dict | None:
        """The first unification (not to be changed: it may be the one remembered for the next call).

        An expression without bindings that reads only stored beliefs is solved again only when a relation it
        reads has changed (or the plans' epoch moved): relations' versions and the epoch only grow, so their
        sum tells.
        """
        if self._heap:
            self._expire_due()
        compiled = self._queries.get(expression)
        if compiled is None:
            compiled = self._compile(expression)
        relations = self._relations if compiled.derived is None else self._rulebook.ready(compiled.derived)
        if bindings:
            return compiled.first(relations, self._bind(bindings))
        reads = compiled.reads
        if reads is None or not self.standing_answers:  # a computed predicate: asked every time
            return compiled.first(relations)
        stamp = relations.epoch
        for signature in reads:
            rel = relations.get(signature)
            if rel is not None:
                stamp += rel.version + 1
        if compiled.stamp != stamp:
            compiled.answer, compiled.stamp = compiled.first(relations), stamp
        return compiled.answer

    def _compile(self, expression: Expression) -> CompiledQuery:
        if type(expression) is Struct:
            conjunction = Conjunction((Goal(expression),), format_term(expression))
        elif type(expression) is Conjunction:
            conjunction = expression
        elif isinstance(expression, str):
            conjunction = parse_expression(expression)
        else:
            raise BeliefSyntaxError(repr(expression), "a belief expression is text")
        self._check_vocabulary(conjunction)
        compiled = CompiledQuery(respell(conjunction, self._spellings), self._is_exclusive, self._answered)
        predicates = conjunction.predicates
        book = self._rulebook
        derived = tuple(p for p in predicates if book.is_derived(p)) if book else ()
        compiled.derived = derived or None
        if not derived:
            compiled.probe = compiled.probe_in(self._relations)
        compiled.reads = (None if any(p in self._answered or (book and book.volatile(p)) for p in predicates)
                          else tuple(sorted(p for p in predicates if p not in BUILTIN_PREDICATES)))
        if len(self._queries) > 4096:
            self._queries.clear()
        self._queries[expression] = compiled
        return compiled

    @staticmethod
    def _bind(bindings: Mapping[str, Any]) -> dict:
        return {Var(name): from_python(value) for name, value in bindings.items()}

    def _check_vocabulary(self, conjunction: Conjunction) -> None:
        if not self._vocabulary:
            return
        book = self._rulebook
        for name, arity in conjunction.predicates:
            if (name, arity) in self._computed or (name, arity) in BUILTIN_PREDICATES:
                continue
            if book is not None and book.is_derived((name, arity)):
                continue
            declared = self._vocabulary.get(name)
            if declared is None:
                raise UnknownPredicateError(name, conjunction.text or str(conjunction))
            if declared != arity:
                raise UnknownPredicateError(
                    f"{name}/{arity}",
                    conjunction.text or str(conjunction),
                    f"{name} takes {declared} argument{'s' if declared != 1 else ''}",
                )

    def _parse_belief(self, text: Any) -> Struct:
        if not isinstance(text, str):
            raise BeliefSyntaxError(repr(text), "a belief is text or a term")
        belief = parse_belief(text)
        self._check_vocabulary(Conjunction((Goal(belief),), text))
        return belief

    def _parse_goal(self, text: Any) -> Struct:
        if not isinstance(text, str):
            raise BeliefSyntaxError(repr(text), "a belief pattern is text or a term")
        expr = parse_expression(text)
        if len(expr.literals) != 1 or type(expr.literals[0]) is not Goal:
            raise BeliefSyntaxError(text, "expected a single predicate such as visible(?X)")
        self._check_vocabulary(expr)
        return expr.literals[0].term
