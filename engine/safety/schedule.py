"""When a safety rule's condition can next change: the monitors' incremental evaluation.

A rule is checked again when a belief it reads changes, as the reactive rules are, except for values that move
continuously: a drone's position (its own, a fleet mate's) and what is computed from it (a distance, the charge a
return home takes, the stopping point), and the mission's time. A condition over those compares numbers
(``?d < 5``); how far each comparison is from flipping is a budget that the value's motion must spend before the
comparison can flip. Each drone's position belief drives odometers (the path its believed position has travelled:
in 3-D, horizontally, along each axis), and a value's rate says how much it can move per meter of such a path
(a distance to a fixed point: at most one meter per meter) or per second (the mission's time), plus what it may
jump at once (rounding). A check leaves *entries*: "check me again when this odometer reaches this reading" or "at
this time"; until one is reached the rule cannot have flipped. Far from a keep-out volume, or while the drone
hovers, the rule sleeps; flying at it, it is checked as often as its distance requires. The bound is the belief's
own path, so noise in the position and the vehicle's speed need no allowance: what the rule reads is what is
measured.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from aeroexec.beliefs import Comparison, Conjunction, Goal, Negation, Var
from aeroexec.engine.safety.chains import compile_chain, variables

Signature = tuple[str, int]
AXES = ("x", "y", "z", "h", "p")  # the odometers of a drone: along each axis, horizontal path, 3-D path
TIME = None  # the key of the time "odometer" in an entry
Entry = tuple[Any, float]  # (odometer key (who, axis) or TIME, the reading at which to check again)
Coefficient = float | Callable[[], float]


@dataclass(frozen=True)
class Rate:
    """How fast a value can move: ``per_second`` of time, ``per_meter`` of a drone's path (``(who, axis,
    coefficient)``: ``who`` an atom or a variable of the condition), and by how much it may ``jump`` at once. A
    coefficient is a number, or a function giving it now (the charge a meter home takes depends on the wind)."""

    per_second: Coefficient = 0.0
    per_meter: tuple[tuple[Any, str, Coefficient], ...] = ()
    jump: Coefficient = 0.0

    def __add__(self, other: Rate) -> Rate:
        merged: dict[tuple, Coefficient] = {}
        for who, axis, k in (*self.per_meter, *other.per_meter):
            merged[(who, axis)] = _combine(merged[(who, axis)], k, operator.add) if (who, axis) in merged else k
        return Rate(_combine(self.per_second, other.per_second, operator.add),
                    tuple((w, x, k) for (w, x), k in merged.items()), _combine(self.jump, other.jump, operator.add))

    def scaled(self, k: Coefficient) -> Rate:
        return Rate(_combine(self.per_second, k, operator.mul),
                    tuple((w, a, _combine(c, k, operator.mul)) for w, a, c in self.per_meter),
                    _combine(self.jump, k, operator.mul))

    @property
    def moves(self) -> bool:
        return callable(self.per_second) or self.per_second > 0.0 or bool(self.per_meter)


STILL = Rate()


def _combine(a: Coefficient, b: Coefficient, how: Callable[[float, float], float]) -> Coefficient:
    if not callable(a) and not callable(b):
        return how(a, b)
    return lambda: how(_now(a), _now(b))


def _now(k: Coefficient) -> float:
    return k() if callable(k) else k


def _max(a: Rate, b: Rate) -> Rate:
    terms: dict[tuple, Coefficient] = {}
    for w, x, k in (*a.per_meter, *b.per_meter):
        terms[(w, x)] = _combine(terms[(w, x)], k, max) if (w, x) in terms else k
    return Rate(_combine(a.per_second, b.per_second, max), tuple((w, x, k) for (w, x), k in terms.items()),
                _combine(a.jump, b.jump, max))


@dataclass(frozen=True)
class Source:
    """What a predicate's last argument is, as a rate. ``point``: a drone's position (``position(Who, P)``: ``P``
    moves with ``Who``'s path, a destructured ``(?x, ?y, ?z)`` along each axis). Else ``rate`` (its own), plus the
    rates of the arguments ``through`` scaled by ``scale`` (a computed predicate of points), or ``mover(Who)``
    when its first argument is a drone (``battery_to_home(self, B)``); ``reads``: the beliefs a computed one
    consults, whose changes wake the rule; ``follows``: the rated beliefs (positions, the charge) it moves with."""

    rate: Rate = STILL
    through: tuple[int, ...] = ()
    scale: Coefficient = 1.0
    mover: Callable[[Any], Rate] | None = None
    reads: tuple[Signature, ...] = ()
    point: bool = False
    follows: tuple[Signature, ...] = ()  # the rated beliefs it moves with


_OPERATORS = {"=": operator.eq, "!=": operator.ne, "<": operator.lt, ">": operator.gt, "<=": operator.le,
              ">=": operator.ge}


class _Test:
    """One comparison, ready to be checked against a solution: its sides, its operator (``ordered``: it holds
    between numbers only, as the memory compares) and its rate."""

    __slots__ = ("left", "right", "left_var", "right_var", "test", "ordered", "rate", "fixed")

    def __init__(self, comparison: Comparison, rate: Rate) -> None:
        left, right = comparison.left, comparison.right
        self.left_var = type(left) is Var
        self.right_var = type(right) is Var
        self.left = left.name if self.left_var else left
        self.right = right.name if self.right_var else right
        self.test = _OPERATORS[comparison.op]
        self.ordered = comparison.op not in ("=", "!=")
        self.rate = rate
        dynamic = callable(rate.jump) or callable(rate.per_second) or any(callable(k) for _, _, k in rate.per_meter)
        self.fixed = None if dynamic else _figures(rate)  # its figures, when they do not depend on the moment


def _figures(rate: Rate) -> tuple[float, float, tuple, bool]:
    """A rate's figures now: its jump, per second, per meter terms, and whether anything moves it."""
    per_second = _now(rate.per_second)
    terms = tuple((who, axis, _now(k)) for who, axis, k in rate.per_meter)
    return _now(rate.jump), per_second, terms, per_second > 0.0 or bool(terms)


class Plan:
    """A rule's condition split for scheduling: its goals (solved by the memory) and its numeric comparisons
    (checked here, measuring how far each is from flipping). ``None`` from :meth:`of` when a comparison binds a
    variable (``?x = 3`` with ``?x`` free) or reads a predicate with no known rate: such a rule is checked at
    every change of what it reads."""

    def __init__(self, goals: Conjunction, tests: tuple[_Test, ...]) -> None:
        self.goals, self.tests = goals, tests
        self.solve: Callable[[Any], list[dict]] = lambda memory: memory.query_all(goals)

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
            if source is not None and term.args:
                _give(term.args[-1], _rate(source, term.args, rates), rates, source.point)
            bound |= set(variables(term))
        for comparison in comparisons:
            if any(v not in bound for v in (*variables(comparison.left), *variables(comparison.right))):
                return None
        tests = tuple(_Test(c, _rate_of(c.left, rates) + _rate_of(c.right, rates)) for c in comparisons)
        text = ", ".join(str(g) for g in goals) or "true"
        return cls(Conjunction(tuple(goals), text), tests)

    def compile(self, memory: Any) -> None:
        """Solve the goals as a chain where they form one (:mod:`aeroexec.engine.safety.chains`)."""
        chain = compile_chain(self.goals, memory)
        if chain is not None:
            self.solve = chain

    def verdict(self, solutions: list[dict], now: float, reading: Callable[[Any], float]) -> \
            tuple[bool, list[Entry], dict]:
        """Whether the condition holds over ``solutions`` of its goals, the entries (odometer readings, times)
        before none of which that can change, and the solution that decided it (the one that holds, or the
        nearest to holding). ``reading(key)`` is an odometer's reading now."""
        best_holding, holding_score, holding_entries = None, -1.0, None
        entries: list[Entry] = []
        nearest, nearest_score = None, math.inf
        for solution in solutions:
            true, found, score = self._solution(solution, now, reading)
            if true:
                if score > holding_score:  # it stays true while any holding solution does: follow the surest
                    best_holding, holding_score, holding_entries = solution, score, found
            else:
                entries.extend(found)  # any of them may come to hold
                if score < nearest_score:
                    nearest, nearest_score = solution, score
        if best_holding is not None:
            return True, holding_entries, best_holding
        return False, entries, nearest or (solutions[0] if solutions else {})

    def _solution(self, solution: dict, now: float, reading: Callable[[Any], float]) -> \
            tuple[bool, list[Entry], float]:
        """Whether the comparisons hold for one solution, the entries before which that cannot change, and a
        score: how far (in budget per unit of rate) it is from changing."""
        to_false: list[Entry] = []
        to_true: list[Entry] | None = None
        true_score, false_score = math.inf, -1.0
        all_true = True
        for test in self.tests:
            left = solution.get(test.left) if test.left_var else test.left
            right = solution.get(test.right) if test.right_var else test.right
            figures = test.fixed or _figures(test.rate)
            kind, other = type(left), type(right)
            if (kind is float or kind is int) and (other is float or other is int):
                true = test.test(left, right)
                budget = abs(left - right) - figures[0]
            else:
                true = not test.ordered and test.test(left, right)
                budget = None
            found, score = _entries(figures, budget, solution, now, reading)
            if true:
                to_false.extend(found)
                true_score = min(true_score, score)
            else:
                all_true = False
                if score > false_score:  # all must flip for it to hold: any one is a bound, the surest kept
                    to_true, false_score = found, score
        if all_true:
            return True, to_false, true_score
        return False, to_true or [], false_score


def _entries(figures: tuple, budget: float | None, solution: dict, now: float,
             reading: Callable[[Any], float]) -> tuple[list[Entry], float]:
    """Where a comparison with ``budget`` left before it flips may flip at the earliest: its budget shared
    between what moves it (an entry each), and a score (budget over the total rate). ``figures``: its rate's."""
    jump, per_second, terms, moves = figures
    if not moves:
        if jump > 0.0 and (budget is None or budget <= 0.0):
            return [(TIME, now)], 0.0  # only its rounding moves it, and it is within that of flipping
        return [], math.inf
    if budget is None or budget <= 0.0:
        return [(TIME, now)], 0.0
    share = budget / (len(terms) + (1 if per_second > 0.0 else 0))
    found: list[Entry] = []
    total = per_second
    if per_second > 0.0:
        found.append((TIME, now + share / per_second))
    for who, axis, k in terms:
        if k <= 0.0:
            continue
        if type(who) is Var:
            who = solution.get(who.name)
        key = (who, axis)
        found.append((key, reading(key) + share / k))
        total += k
    if total <= 0.0:
        return [], math.inf
    return found, budget / total


def _rate(source: Source, args: tuple, rates: Mapping[Var, Rate]) -> Rate:
    """The rate of the last argument of a goal of ``source``'s predicate with ``args``."""
    first = args[0] if args else None
    if source.point:
        return Rate(per_meter=((first, "p", 1.0),))
    rate = source.rate
    if source.mover is not None and (type(first) is str or type(first) is Var and first not in rates):
        rate = rate + source.mover(first)  # a drone, by name (self) or a variable naming one (a point has a rate)
    moved = STILL
    for index in source.through:
        if index < len(args) - 1:
            moved = moved + _rate_of(args[index], rates)
    return rate + moved.scaled(source.scale) if moved.moves or moved.jump else rate


def _give(arg: Any, rate: Rate, rates: dict[Var, Rate], point: bool) -> None:
    if type(arg) is Var:
        rates[arg] = _max(rates.get(arg, STILL), rate)
    elif isinstance(arg, tuple):  # a list term too
        if point and len(arg) == 3 and rate.per_meter:  # (?x, ?y, ?z): each moves along its axis
            who = rate.per_meter[0][0]
            for item, axis in zip(arg, "xyz", strict=True):
                _give(item, Rate(per_meter=((who, axis, 1.0),)), rates, False)
            return
        for item in arg:
            _give(item, rate, rates, False)


def _rate_of(term: Any, rates: Mapping[Var, Rate]) -> Rate:
    if type(term) is Var:
        return rates.get(term, STILL)
    if isinstance(term, tuple):
        found = STILL
        for item in term:
            found = _max(found, _rate_of(item, rates))
        return found
    return STILL


def goal_literals(condition: Conjunction) -> Conjunction:
    """The goals of a condition without its comparisons and negations: what it read, to say why it broke."""
    goals = tuple(lit for lit in condition.literals if type(lit) is Goal)
    return Conjunction(goals, ", ".join(str(g) for g in goals))


__all__ = ["AXES", "TIME", "Plan", "Rate", "STILL", "Source", "goal_literals"]
