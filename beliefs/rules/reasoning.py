"""Rules in the belief memory: adding them (checked, put in strata) and asking why a belief holds or not.

:class:`Reasoning` is the part of :class:`~aeroexec.beliefs.memory.BeliefMemory` that deals with rules; the
memory answers derived predicates through its :class:`~aeroexec.beliefs.rules.derivation.RuleBook`.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from aeroexec.beliefs.errors import EvaluationRefused, RuleError, RuleProblem
from aeroexec.beliefs.expression import Conjunction, Goal, Rule
from aeroexec.beliefs.parser import parse_rules
from aeroexec.beliefs.rules.derivation import RuleBook
from aeroexec.beliefs.rules.joins import Budget
from aeroexec.beliefs.rules.program import Vocabulary, check, stratify
from aeroexec.beliefs.rules.proofs import Proof, Prover
from aeroexec.beliefs.spellings import respell
from aeroexec.beliefs.terms import Struct, format_term


class Reasoning:
    """Rules of a belief memory (mixed into :class:`~aeroexec.beliefs.memory.BeliefMemory`)."""

    _rulebook: RuleBook | None
    _rule_budget: Budget
    _vocabulary: dict[str, int]
    _computed: dict
    _answered: dict  # computed predicates and shared beliefs: what changes without this memory's writes
    _relations: Any
    _spellings: dict
    _multivalued: set[str]
    _queries: dict

    def add_rules(self, rules: str | Iterable[Rule], file: str = "", first_line: int = 1) -> list[Rule]:
        """Add rules, and facts as beliefs: text as in a rules file (``head :- body.``), or :class:`Rule` records.

        Raises :class:`RuleError` listing every problem with its file and line (syntax, an unsafe rule, a negation
        that cannot be stratified, a rule deriving a stored or computed predicate, an unknown predicate); then
        nothing is added. Returns the rules and facts read.
        """
        rules = parse_rules(rules, file, first_line) if isinstance(rules, str) else list(rules)
        book = self._rulebook
        program = [*(book.rules if book else ()), *(r for r in rules if r.body.literals)]
        derived = {r.head.name for r in program}
        told: dict[str, int] = {}  # the first fact of a predicate declares it; another arity is refused
        for r in rules:
            if not r.body.literals and r.head.name not in derived:
                told.setdefault(r.head.name, r.head.arity)
        vocabulary = Vocabulary({**told, **self._vocabulary},  # the facts given with the rules declare theirs
                                {s: inputs for s, (_, inputs) in self._computed.items()}, bool(self._vocabulary))
        problems = check(program, vocabulary) + check([r for r in rules if not r.body.literals], vocabulary)
        strata, unstratified = stratify(program, vocabulary.computed) if not problems else ([], [])
        if problems or unstratified:
            raise RuleError(problems + unstratified)
        if book is None:
            book = self._rulebook = RuleBook(self._relations, self._is_exclusive, self._answered,
                                             lambda body: respell(body, self._spellings))
            book.budget = self._rule_budget
        self._multivalued |= derived  # a derived predicate holds a set of beliefs
        for (name, _), rel in self._relations.items():
            if name in derived:
                rel.by_key = None
        book.load(program, strata)
        book.share({s for s, (_, inputs) in self._answered.items() if inputs is None})
        self._queries.clear()
        for fact in rules:
            if not fact.body.literals:
                if fact.head.name not in self._vocabulary:  # facts written with rules are sets, as in Datalog
                    self._multivalued.add(fact.head.name)
                    if self._vocabulary:
                        self.declare(fact.head.name, fact.head.arity, multivalued=True)  # type: ignore[attr-defined]
                    rel = self._relations.get(fact.head.signature)
                    if rel is not None:
                        rel.by_key = None
                self.add(fact.head)
        return rules

    def limit_rules(self, work: int | None, why: str = "", per_step: bool = False) -> None:
        """Bound the work one ask may spend evaluating rules (``work`` units: a partial answer built or a derived
        belief stored is one; None: no bound). Past it the ask raises :class:`EvaluationRefused` naming the rule's
        file:line, having built no more than that; asked again while the beliefs the rules read are the same, it
        is refused at once. ``why`` is said in the refusal (`` (rules in flight ...)``). ``per_step``: the bound
        holds for every ask between two calls of :meth:`renew_rules` together (an engine's step), not per ask."""
        budget = self._rule_budget
        budget.work, budget.why, budget.per_ask, budget.spent = work, why, not per_step, 0

    def renew_rules(self) -> None:
        """A new step: the work of :meth:`limit_rules` (``per_step``) may be spent again."""
        self._rule_budget.spent = 0

    def try_rules(self) -> list[RuleProblem]:
        """Derive every derived predicate from the beliefs held now, within the bound of :meth:`limit_rules`, each
        as if asked first and alone: the evaluations refused, as problems with their rule's file and line (empty
        when all fit). A rules file is tried so before flight, with its facts."""
        book = self._rulebook
        if book is None or not book.derived:
            return []
        try:
            book.trial()
        except EvaluationRefused as refused:
            return [RuleProblem(f"{refused.detail} before flight, with the facts given", refused.file,
                                refused.line)]
        return []

    @property
    def rules(self) -> tuple[Rule, ...]:
        """The rules the memory derives beliefs by, in the order they were added."""
        return tuple(self._rulebook.rules) if self._rulebook else ()

    def is_derived(self, name: str, arity: int) -> bool:
        """True when rules derive ``name/arity``."""
        return self._rulebook is not None and self._rulebook.is_derived((name, arity))

    def reads(self, predicates: Iterable[tuple[str, int]]) -> tuple[frozenset[tuple[str, int]], bool]:
        """The stored predicates that ``predicates`` read, through the rules deriving them (their own stored
        beliefs included), and whether any of them reads a computed predicate or shared beliefs (which change
        without a belief of this memory doing so)."""
        found: set[tuple[str, int]] = set()
        computed = False
        book = self._rulebook
        todo, seen = list(predicates), set()
        while todo:
            signature = todo.pop()
            if signature in seen:
                continue
            seen.add(signature)
            if signature in self._answered:
                computed = True
            found.add(signature)
            if book is not None and book.is_derived(signature):
                todo.extend(p for rule in book.rules if rule.head.signature == signature
                            for p in rule.body.predicates)
        return frozenset(found), computed

    def why(self, expression: str | Conjunction | Struct) -> list[Proof] | None:
        """Why the expression holds: a :class:`Proof` of each of its literals for its first answer (the rules and
        beliefs used), or None when it does not hold."""
        return Prover(self).why(self._conjunction(expression))

    def why_not(self, expression: str | Conjunction | Struct) -> list[str]:
        """Why the expression does not hold: the first literal that fails, with the values known by then and what
        the memory holds for it, and for a derived goal the part of each of its rules that fails. Empty when it
        holds."""
        return Prover(self).why_not(self._conjunction(expression))

    def _conjunction(self, expression: str | Conjunction | Struct) -> Conjunction:
        if type(expression) is Struct:
            return Conjunction((Goal(expression),), format_term(expression))
        return self.check(expression)  # type: ignore[attr-defined]


__all__ = ["Proof", "Reasoning"]
