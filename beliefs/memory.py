"""The belief memory (paper section 5.1): add, remove and consult symbolic beliefs, and derive them by rules.

Beliefs are ground terms such as ``charge(battery, 80)``. The memory keeps them
consistent (adding a value of a mutually exclusive predicate retracts the old
one), forgets beliefs whose persistence has run out, answers belief expressions
by unification through its indexes (an expression read once, checked against the vocabulary, compiled into a
query plan kept per text, ``beliefs/query.py``, and answered from its standing answer while the relations it
reads stand), derives beliefs by rules (``beliefs/rules/``: checked and put in strata when added, evaluated
bottom-up and kept up to date by differences, explained by proofs), and tells listeners of every change.
It is not thread-safe: the engine serializes access to it on its own loop.
"""

from __future__ import annotations

import heapq
import logging
import time
from collections.abc import Callable, Iterable, Iterator, Mapping

from aeroexec.beliefs.changes import BeliefChange, belief_change
from aeroexec.beliefs.errors import (
    BeliefError,
    BeliefSyntaxError,
    EvaluationRefused,
    RuleError,
    RuleProblem,
)
from aeroexec.beliefs.expression import BUILTIN_PREDICATES, Conjunction, Goal, Rule
from aeroexec.beliefs.parser import (
    check_predicates,
    parse_belief,
    parse_expression,
    parse_rules,
    read_flat_fact_parts,
    read_flat_parts,
)
from aeroexec.beliefs.query import CompiledQuery
from aeroexec.beliefs.relation import PRESENT, Relation, Relations
from aeroexec.beliefs.rules.budget import Budget
from aeroexec.beliefs.shared import SharedView
from aeroexec.beliefs.spellings import respell, respell_term, spelling_table
from aeroexec.beliefs.steps import FactStep
from aeroexec.beliefs.terms import Struct, Var, format_term, from_python, to_python

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:  # the rules' modules are imported when rules are first added, proofs when first asked for
    from typing import Any

    from aeroexec.beliefs.rules.derivation import RuleBook
    from aeroexec.beliefs.rules.proofs import Proof

#: what a memory is asked: text, a parsed expression, or one term
Expression = str | Conjunction | Struct
_UNANSWERED = object()  # a question the memory's quick reading leaves to the compiled query
_ANONYMOUS_MARK = Var("?")[1]  # the second character of an anonymous variable's name (?#1), never a named one's
_PLAIN = frozenset((str, int, float, Struct))  # values that are their own Python value (to_python)

log = logging.getLogger(__name__)

__all__ = ["BeliefChange", "BeliefMemory"]

class BeliefMemory:
    """An indexed memory of beliefs answering belief expressions by unification.

    ``multivalued`` names predicates whose values are not mutually exclusive;
    ``persistence`` maps a predicate to its lifetime in seconds (permanent
    otherwise), measured on ``clock`` (a callable or an object with ``now()``);
    ``predicates`` declares the vocabulary (name -> arity): once declared, an
    expression using an unknown predicate is refused.
    """

    def __init__(
        self,
        multivalued: Iterable[str] = (),
        persistence: Mapping[str, float] | None = None,
        clock: Any = None,
        predicates: Mapping[str, int] | None = None,
    ) -> None:
        self._relations = Relations()
        self._multivalued = set(multivalued)
        self._persistence: dict[str, float] = dict(persistence or {})
        if clock is None:
            clock = time.monotonic
        self._now: Callable[[], float] = clock.now if hasattr(clock, "now") else clock
        self._vocabulary: dict[str, int] = dict(predicates or {})
        self._spellings: dict[str, dict[str, str | tuple[str, ...]]] = {}
        self._computed: dict[tuple[str, int], tuple[Callable, int]] = {}
        #: what questions are answered by besides stored beliefs: computed predicates and shared beliefs
        self._answered: dict[tuple[str, int], tuple[Any, int | None]] = {}
        self._queries: dict[Any, CompiledQuery] = {}
        self._asked_once: dict[str, None] = {}  # texts answered without compiling them (compiled when asked again)
        #: the relations a question asked once reads straight, by signature: stored beliefs (not computed, shared,
        #: derived or respelled; declared, if there is a vocabulary), found so by :meth:`_quick_relation`
        self._quick: dict[tuple[str, int], Relation] = {}
        self._listeners: list[Callable[[BeliefChange], None]] = []  # of every change
        self._named: dict[str, list[Callable[[BeliefChange], None]]] = {}  # predicate name -> its listeners
        self._listening = False  # whether anyone listens
        # predicate name -> who hears its changes (every change's listeners, then its own), made on its first change
        # after a subscription changed: a change calls a tuple instead of copying the lists
        self._hearing: dict[str, tuple[Callable[[BeliefChange], None], ...]] = {}
        self._expiry: dict[tuple, float] = {}
        self._heap: list[tuple[float, int, tuple, tuple]] = []
        self._sequence = 0
        self._changes = 0
        #: a number that moves with every change that can change an answer (a belief added, removed or expired, a
        #: declaration, a registered function, shared beliefs, rules, their bound): while it stands, a question
        #: :meth:`holds_standing` said stands has the same answer (read it; never write it)
        self.version = 0
        self._rulebook: RuleBook | None = None
        self._rule_budget = Budget()  # what one ask may spend evaluating rules (limit_rules)
        #: answer a repeated question from its last answer while the relations it reads stand (off: solve it
        #: every time, as benchmarks do to measure solving)
        self.standing_answers = True

    # -- configuration ------------------------------------------------------------
    def declare(
        self,
        name: str,
        arity: int,
        multivalued: bool = False,
        persistence: float | None = None,
        values: Iterable[str] = (),
        aliases: Mapping[str, Iterable[str]] | None = None,
    ) -> None:
        """Add a predicate to the vocabulary, with its exclusivity and persistence; ``values``: the atoms its
        last argument takes, matched without regard to case (``LOW`` is ``low``); ``aliases``: names for
        several of them in expressions (``flying``: hovering or moving)."""
        self._vocabulary[name] = arity
        values = tuple(values)
        if values or aliases:
            self._spellings[name] = spelling_table(values, aliases)
        if multivalued:
            self._multivalued.add(name)
        if persistence is not None:
            self._persistence[name] = float(persistence)
        self._forget_plans()
        self.version += 1

    def accepts(self, name: str) -> bool:
        """True when beliefs of predicate ``name`` may be stored without declaring it (declared, or no vocabulary)."""
        return not self._vocabulary or name in self._vocabulary or (
            self._rulebook is not None and any(n == name for n, _ in self._rulebook.derived))

    def register(self, name: str, arity: int, function: Callable, inputs: int | None = None) -> None:
        """Answer ``name/arity`` with ``function`` instead of stored beliefs.

        The first ``inputs`` arguments (default: all but the last) must be bound when
        the goal is reached; the function receives their values and returns ``None``
        for no solution, or the value (a tuple for several) of the remaining arguments.
        """
        inputs = arity - 1 if inputs is None else inputs
        if not 0 <= inputs <= arity:
            raise ValueError(f"{name}/{arity} cannot have {inputs} input arguments")
        self._computed[(name, arity)] = (function, inputs)
        self._answered[(name, arity)] = (function, inputs)
        self._forget_plans()
        self.version += 1

    def share(self, view: SharedView) -> None:
        """Answer questions on ``view``'s predicate from its shared rows too, after the stored ones
        (:mod:`aeroexec.beliefs.shared`: a fleet's positions, held once per process)."""
        self._answered[view.signature] = (view, None)
        if self._rulebook is not None:
            self._rulebook.share({view.signature})
        self._forget_plans()
        self.version += 1

    def announce(self, kind: str, belief: Struct) -> None:
        """Tell the listeners that a shared belief came (``kind`` "added") or went ("removed"), reason "shared":
        what watches this memory's beliefs (rules, safety monitors) hears of a fleet mate appearing or going,
        though the memory stores nothing."""
        self._notify(kind, belief, "shared")

    def function(self, name: str, arity: int) -> tuple[Callable, int] | None:
        """The function registered for ``name/arity`` and how many input arguments it takes (None: stored beliefs
        or a built-in answer it)."""
        return self._computed.get((name, arity))

    def exclusive(self, name: str) -> bool:
        """Whether a belief of ``name`` replaces the one with the same other arguments (one value for each key)."""
        return name not in self._multivalued

    def lifetime(self, name: str) -> float | None:
        """How long a belief of predicate ``name`` lasts once added (seconds), None when it is permanent."""
        return self._persistence.get(name)

    @property
    def lifetimes(self) -> Mapping[str, float]:
        """The predicates whose beliefs do not last (name -> lifetime in seconds); read it, do not change it."""
        return self._persistence

    def is_computed(self, name: str, arity: int) -> bool:
        """True when ``name/arity`` is answered by a registered function or a built-in, not by stored beliefs."""
        return (name, arity) in self._computed or (name, arity) in BUILTIN_PREDICATES

    @property
    def changes(self) -> int:
        """How many changes (a belief added or removed) the memory has had: a version that moves with every one."""
        return self._changes

    def subscribe(self, listener: Callable[[BeliefChange], None],
                  names: Iterable[str] | None = None) -> Callable[[], None]:
        """Call ``listener`` with every :class:`BeliefChange` (only of the predicates ``names``, if given: a
        listener in the engine's tick need not be called for the rest); returns an unsubscribe function."""
        lists = [self._listeners] if names is None else [self._named.setdefault(n, []) for n in set(names)]
        for found in lists:
            found.append(listener)
        self._listening = True
        self._hearing = {}

        def unsubscribe() -> None:
            for found in lists:
                if listener in found:
                    found.remove(listener)
            self._listening = bool(self._listeners) or any(self._named.values())
            self._hearing = {}
        return unsubscribe

    # -- changes ------------------------------------------------------------------
    def add(self, belief: str | Struct) -> bool:
        """Add a ground belief; returns False when it was already there (its lifetime renews)."""
        if type(belief) is Struct:
            name, args = belief.name, belief.args
        else:
            read = read_flat_fact_parts(belief) if type(belief) is str and len(belief) < 1000 else None
            if read is None or (self._vocabulary and self._vocabulary.get(read[0]) != len(read[1])):
                belief = self._parse_belief(belief)  # the grammar's reading, and the vocabulary's verdict
                name, args = belief.name, belief.args
            else:
                (name, args), belief = read, None  # its term is built only if something needs it
        if self._spellings and name in self._spellings:
            belief = respell_term(Struct(name, args) if belief is None else belief, self._spellings)
            name, args = belief.name, belief.args
        if self._heap:
            self._expire_due()
        signature = (name, len(args))
        rel = self._relations.get(signature)
        if rel is None:
            rel = self._new_relation(Struct(name, args) if belief is None else belief)
        ttl = self._persistence.get(name) if self._persistence else None
        if ttl is not None:
            self._schedule(signature, args, ttl)
        displaced = rel.insert(args)
        if displaced is PRESENT:
            return False
        self.version += 1
        if displaced is None:
            self._changes += 1
            size = len(rel.rows)
            if not size & (size - 1):
                self._relations.epoch += 1
        else:
            self._changes += 2
            if self._expiry:
                self._expiry.pop((signature, displaced), None)
            if self._listening:  # the value it replaced, then itself: every listener hears the removal first
                self._notify("removed", Struct(name, displaced), "replaced")
                self._notify("added", Struct(name, args) if belief is None else belief, "add")
            return True
        if self._listening:
            self._notify("added", Struct(name, args) if belief is None else belief, "add")
        return True

    def restore(self, belief: str | Struct, remaining: float | None = None) -> bool:
        """Add a belief that was held before (a resumed run): a belief of a persistent predicate lasts only the
        ``remaining`` seconds it had left (its whole lifetime when None)."""
        added = self.add(belief)
        term = belief if type(belief) is Struct else self._parse_belief(belief)
        if remaining is not None and self._persistence.get(term.name) is not None:
            if self._spellings and term.name in self._spellings:
                term = respell_term(term, self._spellings)
            self._schedule((term.name, len(term.args)), term.args, max(0.0, remaining))
        return added

    def add_all(self, beliefs: Iterable[str | Struct]) -> int:
        """Add many beliefs; returns how many were new."""
        return sum(1 for b in beliefs if self.add(b))

    def remove(self, pattern: str | Struct) -> int:
        """Remove every belief matching ``pattern`` (variables allowed); returns how many."""
        goal = pattern if type(pattern) is Struct else self._parse_goal(pattern)
        found = self.matching(goal)
        for belief in found:
            self._delete(goal.signature, self._relations[goal.signature], belief.args, "remove")
        return len(found)

    def clear(self) -> None:
        """Forget every belief."""
        for signature, rel in list(self._relations.items()):
            for args in list(rel.rows):
                self._delete(signature, rel, args, "clear")

    # -- consulting ---------------------------------------------------------------
    def query(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> dict | None:
        """The first unification as ``{"?X": value}``; ``{}`` if a ground expression holds; None.

        ``bindings`` gives values to variables before solving (``{"?Y": (1, 2, 3)}``).
        """
        compiled = self._queries.get(expression)
        if compiled is not None:
            if compiled.probe is not None and not bindings and not self._heap:
                return compiled.probe()  # one look-up: cheaper than the standing answer's check
        elif not bindings and type(expression) is str:
            answer = self._at_once(expression)
            if answer is not _UNANSWERED:
                return answer
        answer = self._answer(expression, bindings)
        return None if answer is None else dict(answer)

    def query_all(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> list[dict]:
        """Every unification of the expression, as a list of ``{"?X": value}`` dictionaries."""
        compiled, relations = self._prepared(expression)
        return compiled.all(relations, self._bind(bindings) if bindings else None)

    def count(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> int:
        """How many unifications the expression has (``len(query_all(...))``), none of them built as a dictionary: a
        single goal of distinct variables is the size of its relation, derived or stored."""
        compiled, relations = self._prepared(expression)
        return compiled.count(relations, self._bind(bindings) if bindings else None)

    def answers(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> Iterator[tuple]:
        """Every unification as a tuple of the values of the expression's variables, in the order they first
        appear (``reachable(?A, ?B)``: ``(a, b)`` pairs), without a dictionary per answer. The answers are taken
        when it is called: changing the memory while reading them does not change what is read."""
        compiled, relations = self._prepared(expression)
        return compiled.tuples(relations, self._bind(bindings) if bindings else None)

    def holds(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> bool:
        """True when the expression has at least one unification."""
        if not bindings and type(expression) is str and expression not in self._queries:
            answer = self._at_once(expression)
            if answer is not _UNANSWERED:
                return answer is not None
        return self._answer(expression, bindings) is not None

    def holds_standing(self, expression: Expression) -> tuple[bool, int]:
        """:meth:`holds`, and the :attr:`version` its answer stands at: while ``version`` is that number, the
        expression has the same answer (a behavior tree's condition asks again only when it moved). -1 when the
        answer may change with the version standing: it reads a computed predicate, shared beliefs or beliefs that
        expire (by time, not by a change), or the question is not kept yet (asked the first time)."""
        compiled = self._queries.get(expression)
        if compiled is None:
            held = self.holds(expression)
            compiled = self._queries.get(expression)
        else:  # holds(), for a question kept
            held = self._answer(expression, None) is not None
        return held, self.version if compiled is not None and compiled.lasting and self.standing_answers else -1

    def consult(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> tuple[bool, dict]:
        """The paper's ``consultBelief``: ``(success, unification)`` of the first solution."""
        found = self.query(expression, bindings)
        return (found is not None, found or {})

    def check(self, expression: str | Conjunction) -> Conjunction:
        """Parse an expression and check its predicates against the vocabulary, without solving."""
        conjunction = expression if type(expression) is Conjunction else parse_expression(expression)
        self._check_vocabulary(conjunction)
        return conjunction

    # -- inspection ---------------------------------------------------------------
    def __len__(self) -> int:
        if self._heap:
            self._expire_due()
        return sum(len(r.rows) for r in self._relations.values())

    def __iter__(self) -> Iterator[Struct]:
        if self._heap:
            self._expire_due()
        for (name, _), rel in sorted(self._relations.items()):
            for args in sorted(rel.rows, key=format_term):
                yield Struct(name, args)

    def __contains__(self, belief: str | Struct) -> bool:
        if type(belief) is not Struct:
            belief = self._parse_belief(belief)
        return self.holds(belief)

    def matching(self, pattern: str | Struct) -> list[Struct]:
        """The stored beliefs that unify with one predicate pattern such as ``visible(?)``."""
        goal = pattern if type(pattern) is Struct else self._parse_goal(pattern)
        if self._spellings:
            goal = respell_term(goal, self._spellings)
        if self._heap:
            self._expire_due()
        rel = self._relations.get(goal.signature)
        if rel is None:
            return []
        rows = FactStep(goal, rel.by_key is not None).matching_rows(rel, {})
        return [Struct(goal.name, args) for args in rows]

    def beliefs(self, predicate: str | None = None) -> list[Struct]:
        """The beliefs (of one predicate, if named), in a stable order: those stored, and for a predicate rules
        derive, every belief they derive (its stored ones included)."""
        book = self._rulebook
        derived = {s for s in book.derived if predicate in (None, s[0])} if book else set()
        found = [b for b in self if (predicate is None or b.name == predicate)
                 and (b.name, len(b.args)) not in derived]
        for name, arity in sorted(derived):
            rows = book.rows((name, arity)).rows
            found.extend(Struct(name, args) for args in sorted(rows, key=format_term))
        return found

    # -- rules ---------------------------------------------------------------------
    def add_rules(self, rules: str | Iterable[Rule], file: str = "", first_line: int = 1) -> list[Rule]:
        """Add rules, and facts as beliefs: text as in a rules file (``head :- body.``), or :class:`Rule` records.

        Raises :class:`RuleError` listing every problem with its file and line (syntax, an unsafe rule, a negation
        that cannot be stratified, a rule deriving a stored or computed predicate, an unknown predicate); then
        nothing is added. Returns the rules and facts read.
        """
        rules = parse_rules(rules, file, first_line) if isinstance(rules, str) else list(rules)
        book = self._rulebook
        if not rules and book is None:  # nothing to add: no rule book yet (a memory without rules needs none)
            return rules
        from aeroexec.beliefs.rules.derivation import RuleBook
        from aeroexec.beliefs.rules.program import Vocabulary, check, stratify

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
        self._forget_plans()
        self.version += 1
        for fact in rules:
            if not fact.body.literals:
                if fact.head.name not in self._vocabulary:  # facts written with rules are sets, as in Datalog
                    self._multivalued.add(fact.head.name)
                    if self._vocabulary:
                        self.declare(fact.head.name, fact.head.arity, multivalued=True)
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
        self.version += 1

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
        from aeroexec.beliefs.rules.proofs import Prover

        return Prover(self).why(self._conjunction(expression))

    def why_not(self, expression: str | Conjunction | Struct) -> list[str]:
        """Why the expression does not hold: the first literal that fails, with the values known by then and what
        the memory holds for it, and for a derived goal the part of each of its rules that fails. Empty when it
        holds."""
        from aeroexec.beliefs.rules.proofs import Prover

        return Prover(self).why_not(self._conjunction(expression))

    def _conjunction(self, expression: str | Conjunction | Struct) -> Conjunction:
        if type(expression) is Struct:
            return Conjunction((Goal(expression),), format_term(expression))
        return self.check(expression)

    # -- internals ----------------------------------------------------------------
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

    def _at_once(self, text: str) -> dict | None | object:
        """The first answer of a question not asked before, when it is one stored goal of the common shape (read by
        hand, no grammar, no plan): ground (``code(o500, 500)``: a membership test) or asking the value its key
        holds (``color(o500, ?C)``: one look-up). :data:`_UNANSWERED` for anything else, and for a question asked a
        second time: that one is compiled and kept (its next asks cost a look-up of the text)."""
        seen = self._asked_once
        if text in seen:
            return _UNANSWERED
        if len(seen) > 4096:
            seen.clear()
        seen[text] = None
        read = read_flat_parts(text, False) if len(text) < 1000 else None
        if read is None:
            return _UNANSWERED
        name, args = read
        signature = (name, len(args))
        if self._heap:
            self._expire_due()
        rel = self._quick.get(signature)
        if rel is None:
            rel = self._quick_relation(signature)
            if rel is None or rel is _UNANSWERED:
                return rel  # no belief of it (None), or not stored beliefs alone
        if "?" not in text:
            return {} if args in rel.rows else None
        last = args[-1]
        by_key = rel.by_key
        if type(last) is not Var or by_key is None or text.count("?") != 1:
            return _UNANSWERED
        row = by_key.get(args[:-1])
        if row is None:
            return None
        if last[1] == _ANONYMOUS_MARK:  # Var.anonymous without the property's call: a named one is ?[A-Za-z0-9_]+
            return {}
        value = row[-1]
        return {str.__str__(last): value if type(value) in _PLAIN else to_python(value)}  # Var.name, to_python

    def _quick_relation(self, signature: tuple[str, int]) -> Relation | None | object:
        """The relation of ``signature`` when a question asked once may read it straight (kept in ``_quick`` until
        the plans are forgotten), None when there is none yet (no belief of it: no answer), :data:`_UNANSWERED` when
        something else answers it (computed, shared, derived, respelled) or the vocabulary refuses it."""
        name, arity = signature
        if (self._vocabulary and self._vocabulary.get(name) != arity) or signature in self._answered \
                or signature in BUILTIN_PREDICATES or name in self._spellings \
                or (self._rulebook is not None and self._rulebook.is_derived(signature)):
            return _UNANSWERED
        rel = self._relations.get(signature)
        if rel is not None:
            self._quick[signature] = rel
        return rel

    def _forget_plans(self) -> None:
        """What was compiled from the vocabulary, the computed and shared predicates and the rules is forgotten:
        one of them changed."""
        self._queries.clear()
        self._quick.clear()

    def _prepared(self, expression: Expression) -> tuple[CompiledQuery, Relations]:
        """The compiled query of ``expression`` and the relations to solve it in (derived ones brought up to date)."""
        if self._heap:
            self._expire_due()
        compiled = self._queries.get(expression)
        if compiled is None:
            compiled = self._compile(expression)
        relations = self._relations if compiled.derived is None else self._rulebook.ready(compiled.derived)
        return compiled, relations

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
        if compiled.reads is not None:  # its answer stands while ``version`` does, unless a belief it reads expires
            found, computed = self.reads(predicates) if derived else (compiled.reads, False)
            compiled.lasting = not computed and not any(name in self._persistence for name, _ in found)
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
        computed = self._computed
        check_predicates(conjunction, self._vocabulary, lambda signature: signature in computed or (
            book is not None and book.is_derived(signature)))

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

    def _is_exclusive(self, name: str) -> bool:
        return name not in self._multivalued

    def _new_relation(self, belief: Struct) -> Relation:
        name, arity = belief.signature
        if self._vocabulary:
            self._check_vocabulary(Conjunction((Goal(belief),), format_term(belief)))
        if (name, arity) in self._computed or (name, arity) in BUILTIN_PREDICATES:
            raise BeliefError(f"{name} is computed by the engine and cannot be stored as a belief")
        rel = Relation(name, arity, self._is_exclusive(name))
        self._relations[(name, arity)] = rel
        self._relations.epoch += 1
        return rel

    def _delete(self, signature: tuple, rel: Relation, args: tuple, reason: str) -> None:
        rel.delete(args)
        self._changes += 1
        self.version += 1
        self._relations.resized(rel)
        self._expiry.pop((signature, args), None)
        if self._listening:
            self._notify("removed", Struct(signature[0], args), reason)

    def _notify(self, kind: str, belief: Struct, reason: str) -> None:
        hearing = self._hearing.get(belief.name)
        if hearing is None:
            hearing = self._heard(belief.name)
        if not hearing:
            return
        change = belief_change(kind, belief, reason, self._now())
        for listener in hearing:
            try:
                listener(change)
            except Exception:  # a faulty listener must not corrupt the memory
                log.exception("belief listener %r failed on %s", listener, change)

    def _heard(self, name: str) -> tuple[Callable[[BeliefChange], None], ...]:
        """Who hears the changes of predicate ``name`` (every change's listeners, then its own), kept until a
        subscription changes."""
        named = self._named.get(name) if self._named else None
        hearing = self._hearing[name] = (*self._listeners, *named) if named else tuple(self._listeners)
        return hearing

    def _schedule(self, signature: tuple, args: tuple, ttl: float) -> None:
        due = self._now() + ttl
        self._expiry[(signature, args)] = due
        self._sequence += 1
        heapq.heappush(self._heap, (due, self._sequence, signature, args))

    def _expire_due(self) -> None:
        now = self._now()
        heap = self._heap
        while heap and heap[0][0] <= now:
            due, _, signature, args = heapq.heappop(heap)
            if self._expiry.get((signature, args)) != due:
                continue  # renewed or already removed
            rel = self._relations.get(signature)
            if rel is not None and args in rel.rows:
                self._delete(signature, rel, args, "expired")
            else:
                self._expiry.pop((signature, args), None)

