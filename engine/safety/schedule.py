"""When a safety rule's condition can next change: the monitors' incremental evaluation.

A rule is checked again when a belief it reads changes, as the reactive rules are, except for beliefs whose
values move at a bounded rate (the drone's and its fleet mates' positions, the charge, the mission's time): a
condition over those compares numbers (``?d < 5``), and how far each comparison is from flipping, divided by how
fast its sides can move, is a time before which its truth cannot change (the vehicle's top speed, its battery's
fastest drain; noise and rounding are allowed for). Far from a keep-out volume the rule sleeps; near it, it is
checked at every update. A belief of a rated predicate that appears or goes (a new fleet mate) wakes the rule.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from aeroexec.beliefs import Comparison, Conjunction, Goal, Negation, Var
from aeroexec.beliefs.terms import Struct

Signature = tuple[str, int]


@dataclass(frozen=True)
class Rate:
    """How fast a value can move (units per second) and by how much it may jump at once (noise, rounding)."""

    speed: float = 0.0
    jump: float = 0.0

    def __add__(self, other: Rate) -> Rate:
        return Rate(self.speed + other.speed, self.jump + other.jump)


STILL = Rate()


@dataclass(frozen=True)
class Source:
    """What a predicate's last argument is, as a rate: ``rate`` of its value, ``through`` (an argument whose
    rate adds to it, for computed predicates of a point), ``reads``: the beliefs a computed one consults."""

    rate: Rate = STILL
    through: tuple[int, ...] = ()
    reads: tuple[Signature, ...] = ()
    rated_reads: tuple[Signature, ...] = ()


class Plan:
    """A rule's condition split for scheduling: its goals (solved by the memory) and its numeric comparisons
    (checked here, measuring how far each is from flipping). ``None`` from :meth:`of` when a comparison binds a
    variable (``?x = 3`` with ``?x`` free) or reads a predicate with no known rate: such a rule is checked at
    every change of what it reads."""

    def __init__(self, goals: Conjunction, comparisons: tuple[Comparison, ...], rates: dict[Var, Rate]) -> None:
        self.goals, self.comparisons, self.rates = goals, comparisons, rates

    @classmethod
    def of(cls, condition: Conjunction, sources: Mapping[Signature, Source],
           computed: Callable[[str, int], bool]) -> Plan | None:
        goals: list[Any] = []
        comparisons: list[Comparison] = []
        rates: dict[Var, Rate] = {}
        bound: set[Var] = set()
        for literal in condition.literals:
            if type(literal) is Comparison:
                comparisons.append(literal)
                continue
            goals.append(literal)
            if type(literal) is Negation:
                if any(p in sources or computed(*p) for p in literal.body.predicates):
                    return None  # what it negates moves without a belief changing
                continue
            term = literal.term
            source = sources.get(term.signature)
            if source is None and computed(*term.signature):
                return None  # a built-in or computed predicate whose value moves without a belief changing
            if source is not None and term.args:  # a rated value: its last argument moves at the source's rate
                rate = source.rate
                for index in source.through:
                    if index < len(term.args):
                        rate = rate + _rate_of(term.args[index], rates)
                _give(term.args[-1], rate, rates)
            bound |= set(_variables(term))
        for comparison in comparisons:
            if any(v not in bound for v in (*_variables(comparison.left), *_variables(comparison.right))):
                return None
        text = ", ".join(str(g) for g in goals) or "true"
        return cls(Conjunction(tuple(goals), text), tuple(comparisons), rates)

    def verdict(self, solutions: list[dict]) -> tuple[bool, float, dict]:
        """Whether the condition holds over ``solutions`` of its goals, the seconds before that can change, and
        the solution that decided it (the one that holds, or the nearest to holding)."""
        holding, soonest, latest, nearest = [], math.inf, 0.0, None
        for solution in solutions:
            true, seconds = self._solution(solution)
            if true:
                holding.append(solution)
                latest = max(latest, seconds)
            elif seconds < soonest:
                soonest, nearest = seconds, solution
        if holding:
            return True, latest, holding[0]
        return False, soonest, nearest or (solutions[0] if solutions else {})

    def _solution(self, solution: dict) -> tuple[bool, float]:
        all_true, to_false, to_true = True, math.inf, 0.0
        for comparison in self.comparisons:
            left, right = _value(comparison.left, solution), _value(comparison.right, solution)
            true = _compare(comparison.op, left, right)
            rate = _rate_of(comparison.left, self.rates) + _rate_of(comparison.right, self.rates)
            gap = _gap(left, right)
            seconds = math.inf if rate.speed <= 0 and rate.jump <= 0 else (
                0.0 if rate.speed <= 0 or gap is None else max(gap - rate.jump, 0.0) / rate.speed)
            if rate.speed <= 0 and rate.jump > 0 and gap is not None and gap > rate.jump:
                seconds = math.inf
            if true:
                to_false = min(to_false, seconds)
            else:
                all_true = False
                to_true = max(to_true, seconds)
        return (True, to_false) if all_true else (False, to_true)


def _give(arg: Any, rate: Rate, rates: dict[Var, Rate]) -> None:
    if type(arg) is Var:
        rates[arg] = _max(rates.get(arg, STILL), rate)
    elif isinstance(arg, tuple):  # a list term too
        for item in arg:
            _give(item, rate, rates)


def _rate_of(term: Any, rates: Mapping[Var, Rate]) -> Rate:
    if type(term) is Var:
        return rates.get(term, STILL)
    if isinstance(term, tuple):
        found = STILL
        for item in term:
            found = _max(found, _rate_of(item, rates))
        return found
    return STILL


def _max(a: Rate, b: Rate) -> Rate:
    return Rate(max(a.speed, b.speed), max(a.jump, b.jump))


def _variables(term: Any) -> list[Var]:
    if type(term) is Var:
        return [term]
    if isinstance(term, tuple):
        return [v for item in term for v in _variables(item)]
    if isinstance(term, Struct):
        return [v for item in term.args for v in _variables(item)]
    return []


def _value(term: Any, solution: dict) -> Any:
    return solution.get(str(term)) if type(term) is Var else term


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _gap(left: Any, right: Any) -> float | None:
    return abs(float(left) - float(right)) if _number(left) and _number(right) else None


def _compare(op: str, left: Any, right: Any) -> bool:
    if op == "=":
        return left == right
    if op == "!=":
        return left != right
    if not (_number(left) and _number(right)):
        return False
    return {"<": left < right, ">": left > right, "<=": left <= right, ">=": left >= right}[op]


def goal_literals(condition: Conjunction) -> Conjunction:
    """The goals of a condition without its comparisons and negations: what it read, to say why it broke."""
    goals = tuple(lit for lit in condition.literals if type(lit) is Goal)
    return Conjunction(goals, ", ".join(str(g) for g in goals))


__all__ = ["Plan", "Rate", "STILL", "Source", "goal_literals"]
