"""The belief memory (paper section 5.1): add, remove and consult symbolic beliefs, and derive them by rules.

Beliefs are ground terms such as ``charge(battery, 80)``. The memory keeps them
consistent (adding a value of a mutually exclusive predicate retracts the old
one), forgets beliefs whose persistence has run out, answers belief expressions
by unification through its indexes (``beliefs/consulting.py``), derives beliefs
by rules (``beliefs/rules/derivation.py``), and tells listeners of every change.
It is not thread-safe: the engine serializes access to it on its own loop.
"""

from __future__ import annotations

import heapq
import logging
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

from aeroexec.beliefs.changes import BeliefChange
from aeroexec.beliefs.consulting import Consulting, Expression
from aeroexec.beliefs.errors import BeliefError
from aeroexec.beliefs.expression import BUILTIN_PREDICATES, Conjunction, Goal
from aeroexec.beliefs.parser import parse_expression
from aeroexec.beliefs.query import CompiledQuery
from aeroexec.beliefs.relation import PRESENT, Relation, Relations
from aeroexec.beliefs.rules.derivation import RuleBook
from aeroexec.beliefs.rules.joins import Budget
from aeroexec.beliefs.rules.reasoning import Reasoning
from aeroexec.beliefs.shared import SharedView
from aeroexec.beliefs.spellings import respell_term, spelling_table
from aeroexec.beliefs.steps import FactStep
from aeroexec.beliefs.terms import Struct, format_term

log = logging.getLogger(__name__)

__all__ = ["BeliefChange", "BeliefMemory"]

class BeliefMemory(Reasoning, Consulting):
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
        self._listeners: list[Callable[[BeliefChange], None]] = []  # of every change
        self._named: dict[str, list[Callable[[BeliefChange], None]]] = {}  # predicate name -> its listeners
        self._listening = False  # whether anyone listens
        self._expiry: dict[tuple, float] = {}
        self._heap: list[tuple[float, int, tuple, tuple]] = []
        self._sequence = 0
        self._changes = 0
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
        self._queries.clear()

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
        self._queries.clear()

    def share(self, view: SharedView) -> None:
        """Answer questions on ``view``'s predicate from its shared rows too, after the stored ones
        (:mod:`aeroexec.beliefs.shared`: a fleet's positions, held once per process)."""
        self._answered[view.signature] = (view, None)
        if self._rulebook is not None:
            self._rulebook.share({view.signature})
        self._queries.clear()

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

        def unsubscribe() -> None:
            for found in lists:
                if listener in found:
                    found.remove(listener)
            self._listening = bool(self._listeners) or any(self._named.values())
        return unsubscribe

    # -- changes ------------------------------------------------------------------
    def add(self, belief: str | Struct) -> bool:
        """Add a ground belief; returns False when it was already there (its lifetime renews)."""
        if type(belief) is not Struct:
            belief = self._parse_belief(belief)
        if self._spellings and belief.name in self._spellings:
            belief = respell_term(belief, self._spellings)
        if self._heap:
            self._expire_due()
        args = belief.args
        signature = (belief.name, len(args))
        rel = self._relations.get(signature)
        if rel is None:
            rel = self._new_relation(belief)
        ttl = self._persistence.get(signature[0]) if self._persistence else None
        if ttl is not None:
            self._schedule(signature, args, ttl)
        displaced = rel.insert(args)
        if displaced is PRESENT:
            return False
        if displaced is None:
            self._changes += 1
            size = len(rel.rows)
            if not size & (size - 1):
                self._relations.epoch += 1
        else:
            self._changes += 2
            if self._expiry:
                self._expiry.pop((signature, displaced), None)
            if self._listening:
                self._notify("removed", Struct(signature[0], displaced), "replaced")
        if self._listening:
            self._notify("added", belief, "add")
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
        if compiled is not None and compiled.probe is not None and not bindings and not self._heap:
            return compiled.probe()  # one look-up: cheaper than the standing answer's check
        answer = self._answer(expression, bindings)
        return None if answer is None else dict(answer)

    def query_all(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> list[dict]:
        """Every unification of the expression, as a list of ``{"?X": value}`` dictionaries."""
        if self._heap:
            self._expire_due()
        compiled = self._queries.get(expression)
        if compiled is None:
            compiled = self._compile(expression)
        relations = self._relations if compiled.derived is None else self._rulebook.ready(compiled.derived)
        return compiled.all(relations, self._bind(bindings) if bindings else None)

    def holds(self, expression: Expression, bindings: Mapping[str, Any] | None = None) -> bool:
        """True when the expression has at least one unification."""
        return self._answer(expression, bindings) is not None

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

    # -- internals ----------------------------------------------------------------
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
        self._relations.resized(rel)
        self._expiry.pop((signature, args), None)
        if self._listening:
            self._notify("removed", Struct(signature[0], args), reason)

    def _notify(self, kind: str, belief: Struct, reason: str) -> None:
        named = self._named.get(belief.name) if self._named else None
        if not named and not self._listeners:
            return
        change = BeliefChange(kind, belief, reason, self._now())
        for listener in [*self._listeners, *named] if named else list(self._listeners):
            try:
                listener(change)
            except Exception:  # a faulty listener must not corrupt the memory
                log.exception("belief listener %r failed on %s", listener, change)

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

