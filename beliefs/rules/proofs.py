"""Why a belief holds (its proof: the rules and beliefs used) and why it does not (the goal that failed).

``why`` finds one proof of the first answer of an expression: each goal is shown with what made it true
(a stored belief, a rule with the proofs of its body, a computed predicate, a comparison, a negation no
belief matches). ``why_not`` extends the paper's failure explanations through rules: for a derived goal,
each rule that could derive it names the first part of its body that fails and what the memory holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from aeroexec.beliefs.expression import BUILTIN_PREDICATES, Comparison, Conjunction, Goal, Negation, Rule
from aeroexec.beliefs.terms import Struct, Var, format_term, from_python, is_ground, match, substitute, to_python

MAX_DEPTH = 64  # a proof deeper than this is not looked for (recursion over a long chain)
TRIES = 32  # body solutions tried per rule before giving up on a proof through it
SHOWN = 3  # beliefs shown as "the memory holds"


@dataclass(frozen=True)
class Proof:
    """What made ``statement`` true: ``reason`` in words, the ``rule`` used (if derived) and its ``premises``."""

    statement: str
    reason: str
    rule: Rule | None = None
    premises: tuple[Proof, ...] = ()

    def lines(self, depth: int = 0) -> list[str]:
        out = ["  " * depth + f"{self.statement}  <- {self.reason}"]
        for premise in self.premises:
            out.extend(premise.lines(depth + 1))
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())


class Prover:
    """Proofs and failure explanations over one memory (its rules and beliefs as they are now)."""

    def __init__(self, memory: Any) -> None:
        self.memory = memory
        book = memory._rulebook
        self.rules: dict[tuple[str, int], list[Rule]] = {}
        for rule in (book.rules if book else ()):
            self.rules.setdefault(rule.head.signature, []).append(rule)
        self.proven: dict[Struct, Proof | None] = {}

    # -- why -------------------------------------------------------------------------------------------------------
    def why(self, conjunction: Conjunction) -> list[Proof] | None:
        """A proof of each literal of the first answer of ``conjunction``; None when it does not hold."""
        answer = self.memory.query(conjunction)
        if answer is None:
            return None
        bindings = {Var(name): from_python(value) for name, value in answer.items()}
        return self._literals(conjunction, bindings, frozenset())

    def _literals(self, body: Conjunction, bindings: dict, path: frozenset) -> list[Proof] | None:
        proofs = []
        for lit in body.literals:
            if type(lit) is Goal:
                proof = self.goal(substitute(lit.term, bindings), path)
                if proof is None:
                    return None
                proofs.append(proof)
            elif type(lit) is Comparison:
                shown = Comparison(lit.op, substitute(lit.left, bindings), substitute(lit.right, bindings))
                proofs.append(Proof(str(shown), "the comparison holds"))
            else:
                shown = ", ".join(str(_substituted(inner, bindings)) for inner in lit.body.literals)
                proofs.append(Proof(f"not({shown})", "no belief matches it"))
        return proofs

    def goal(self, term: Struct, path: frozenset) -> Proof | None:
        """A proof of ``term`` (an instance of it, when it holds variables)."""
        signature = term.signature
        memory = self.memory
        if signature in BUILTIN_PREDICATES or signature in memory._computed:
            answer = memory.query(term)
            if answer is None:
                return None
            instance = substitute(term, {Var(k): from_python(v) for k, v in answer.items()})
            return Proof(format_term(instance), "built in" if signature in BUILTIN_PREDICATES
                         else "computed by the engine")
        if signature not in self.rules:
            found = memory.matching(term)
            return Proof(format_term(found[0]), "a belief") if found else None
        if len(path) >= MAX_DEPTH:
            return None
        instances = [term] if is_ground(term) else [substitute(term, {Var(k): from_python(v) for k, v in a.items()})
                                                    for a in memory.query_all(term)[:TRIES]]
        for instance in instances:
            if not is_ground(instance) or instance in path:
                continue
            if instance in self.proven:
                if self.proven[instance] is not None:
                    return self.proven[instance]
                continue
            proof = self._derived(instance, path | {instance})
            if proof is not None or not path:
                self.proven[instance] = proof
            if proof is not None:
                return proof
        return None

    def _derived(self, instance: Struct, path: frozenset) -> Proof | None:
        stored = self.memory._relations.get(instance.signature)
        if stored is not None and instance.args in stored.rows:
            return Proof(format_term(instance), "a belief")
        for rule in self.rules[instance.signature]:
            head: dict = {}
            if not match(rule.head.args, instance.args, head):
                continue
            given = {v.name: to_python(value) for v, value in head.items()}
            for answer in self.memory.query_all(rule.body, given)[:TRIES]:
                bindings = dict(head)
                bindings.update({Var(k): from_python(v) for k, v in answer.items()})
                premises = self._literals(rule.body, bindings, path)
                if premises is not None:
                    return Proof(format_term(instance), f"the rule at {rule.where}: {rule}", rule, tuple(premises))
        return None

    # -- why not ---------------------------------------------------------------------------------------------------
    def why_not(self, conjunction: Conjunction, bindings: dict | None = None, depth: int = 0) -> list[str]:
        """Sentences naming the first literal of ``conjunction`` that fails (with the values known by then) and,
        through the rules of a derived goal, why it fails; empty when the conjunction holds."""
        memory = self.memory
        given = {str(k): to_python(v) for k, v in (bindings or {}).items()}
        known: dict = {}
        literals = conjunction.literals
        for index, lit in enumerate(literals):
            prefix = Conjunction(literals[: index + 1], "")
            found = memory.query(prefix, given)
            if found is None:
                return self._failed(lit, {**given, **known}, depth)
            known = found
        return []

    def _failed(self, lit: Any, known: dict, depth: int) -> list[str]:
        values = {Var(k): from_python(v) for k, v in known.items()}
        shown = _substituted(lit, values)
        sentence = f"{shown} does not hold"
        if type(lit) is Negation:
            inner = Conjunction(tuple(_substituted(i, values) for i in lit.body.literals), "")
            answer = self.memory.query(inner)
            if answer is not None:
                example = ", ".join(str(_substituted(i, {Var(k): from_python(v) for k, v in answer.items()}))
                                    for i in inner.literals)
                sentence += f": {example} holds"
            return [sentence]
        if type(lit) is not Goal:
            return [sentence]
        term = substitute(lit.term, values)
        signature = term.signature
        if signature in BUILTIN_PREDICATES or signature in self.memory._computed:
            return [sentence]
        if signature not in self.rules:
            return [sentence + self._holds(term)]
        lines = [sentence]
        for rule in self.rules[signature]:
            head: dict = {}
            if not _unifiable(rule.head.args, term.args, head):
                continue
            reasons = self.why_not(rule.body, head, depth + 1) if depth < 3 else []
            if reasons:
                lines.append(f"the rule at {rule.where} ({rule}): " + "; ".join(reasons))
        if len(lines) == 1:
            lines.append(f"no rule derives {format_term(term)}" + self._holds(term))
        return lines

    def _holds(self, term: Struct) -> str:
        pattern = _pattern(term)
        holds = self.memory.beliefs(term.name) if self.memory.is_derived(term.name, term.arity) else \
            self.memory.matching(pattern)
        holds = [b for b in holds if b.arity == term.arity]
        if self.memory.is_derived(term.name, term.arity):
            first = pattern.args[0] if pattern.args else None
            holds = [b for b in holds if type(first) is Var or b.args[0] == first]
        if not holds:
            return f"; the memory holds no {format_term(pattern)}"
        shown = ", ".join(format_term(b) for b in holds[:SHOWN]) + (" ..." if len(holds) > SHOWN else "")
        return f"; the memory holds {shown}"


def _substituted(lit: Any, bindings: dict) -> Any:
    if type(lit) is Goal:
        return Goal(substitute(lit.term, bindings))
    if type(lit) is Comparison:
        return Comparison(lit.op, substitute(lit.left, bindings), substitute(lit.right, bindings))
    return Negation(Conjunction(tuple(_substituted(i, bindings) for i in lit.body.literals)))


def _unifiable(pattern: tuple, value: tuple, bindings: dict) -> bool:
    """Match a rule's head against a goal that may hold variables (a goal's variable matches anything)."""
    for p, v in zip(pattern, value, strict=True):
        if type(v) is Var or not is_ground(v):
            continue
        if not match(p, v, bindings):
            return False
    return True


def _pattern(term: Struct) -> Struct:
    """The same predicate with its first argument kept when it is a plain value, the others left open."""
    if not term.args:
        return term
    first = term.args[0]
    keep = first if type(first) is not Var and not isinstance(first, Struct) and is_ground(first) else Var("?")
    return Struct(term.name, (keep, *(Var("?") for _ in term.args[1:])))


__all__ = ["Proof", "Prover"]
