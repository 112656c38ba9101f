"""Executable steps of a query: stored goals, comparisons, built-ins, computed goals, negations.

Each step knows which variables it needs bound before it can run, guesses how many
solutions it will produce (for the planner), and enumerates the extended bindings.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from aeroexec.beliefs.relation import Relation, is_number
from aeroexec.beliefs.terms import Struct, Var, from_python, is_ground, match, substitute, variables

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    #: A range on one variable: (low, high, (low inclusive, high inclusive)); None is unbounded.
    Range = tuple[Any, Any, tuple[bool, bool]]

log = logging.getLogger(__name__)

_NUMERIC_OPS: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b,
    ">": lambda a, b: a > b,
    "<=": lambda a, b: a <= b,
    ">=": lambda a, b: a >= b,
}


class FactStep:
    """A goal answered from stored beliefs through the relation's indexes.

    Solutions walk the index buckets themselves, not copies: the memory never changes while it answers
    (a computed predicate that changed it would end the query with Python's "changed size during iteration").
    """

    __slots__ = (
        "constants",
        "exclusive",
        "flat",
        "nested",
        "pattern",
        "signature",
        "simple",
        "solve",
        "vars",
    )

    def __init__(self, goal: Struct, exclusive: bool) -> None:
        self.signature = goal.signature
        self.pattern = goal.args
        self.constants: tuple = tuple((p, a) for p, a in enumerate(goal.args) if is_ground(a))
        self.simple: tuple = tuple((p, a) for p, a in enumerate(goal.args) if type(a) is Var)
        self.nested: tuple = tuple(
            (p, a) for p, a in enumerate(goal.args) if type(a) is not Var and not is_ground(a)
        )
        self.vars = frozenset(v for a in goal.args for v in variables(a))
        self.exclusive = exclusive and len(goal.args) >= 2
        # flat: every argument a constant or a variable, no variable twice
        self.flat = not self.nested and len({v for _, v in self.simple}) == len(self.simple)
        self.solve = self._solve_flat if self.flat else self._solve_general

    def estimate(self, relations: dict, bound: set, values: dict, ranges: dict) -> float:
        """Rows this goal is expected to yield once the ``bound`` variables have values."""
        rel = relations.get(self.signature)
        if rel is None or not rel.rows:
            return 0.0
        if self.vars <= bound:
            return 0.5  # a membership test
        best = float(len(rel.rows))
        for p, arg in enumerate(self.pattern):
            if is_ground(arg):
                best = min(best, len(rel.bucket(p, arg)))
            elif type(arg) is Var and arg in bound:
                value = values.get(arg, _UNKNOWN)
                size = rel.average_bucket(p) if value is _UNKNOWN else len(rel.bucket(p, value))
                best = min(best, size)
            elif type(arg) is Var and arg in ranges:
                low, high, inclusive = ranges[arg]
                count = rel.count_in_range(p, low, high, inclusive)
                best = min(best, count * max(1.0, rel.average_bucket(p)))
        if self.exclusive and all(is_ground(a) or (type(a) is Var and a in bound) for a in self.pattern[:-1]):
            best = min(best, 1.0)
        return best

    def candidates(self, rel: Relation, bindings: dict, ranges: dict) -> Any:
        """The smallest set of rows that can match, given the current bindings."""
        bound = list(self.constants)
        for p, var in self.simple:
            value = bindings.get(var, _UNKNOWN)
            if value is not _UNKNOWN:
                bound.append((p, value))
        for p, pattern in self.nested:
            value = substitute(pattern, bindings)
            if is_ground(value):
                bound.append((p, value))
        if len(bound) == len(self.pattern):
            row = tuple(v for _, v in sorted(bound, key=lambda pv: pv[0]))
            return (row,) if row in rel.rows else ()
        last = len(self.pattern) - 1
        if self.exclusive and len(bound) == last and all(p != last for p, _ in bound):
            key = tuple(v for _, v in sorted(bound, key=lambda pv: pv[0]))
            row = rel.by_key.get(key) if rel.by_key is not None else None
            return (row,) if row is not None else ()
        if bound:
            return min((rel.bucket(p, v) for p, v in bound), key=len)
        for p, var in self.simple:
            if var in ranges:
                low, high, inclusive = ranges[var]
                return rel.rows_in_range(p, low, high, inclusive)
        return rel.rows

    def matching_rows(self, rel: Relation, bindings: dict) -> list[tuple]:
        """The stored rows that unify with this goal under ``bindings``."""
        pattern = self.pattern
        return [r for r in self.candidates(rel, bindings, {}) if match(pattern, r, dict(bindings))]

    def _solve_general(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        """Solve by unifying each candidate row with the pattern (nested or repeated variables)."""
        rel = relations.get(self.signature)
        if rel is None:
            return
        rows = self.candidates(rel, bindings, ranges)
        pattern = self.pattern
        for row in rows:
            extended = dict(bindings)
            if all(match(pattern[p], row[p], extended) for p in range(len(row))):
                yield extended


    def _solve_flat(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        """Solve a goal whose arguments are constants and distinct variables, without unifying."""
        rel = relations.get(self.signature)
        if rel is None:
            return
        checks = list(self.constants)
        free = []
        for p, var in self.simple:
            value = bindings.get(var, _UNKNOWN)
            if value is _UNKNOWN:
                free.append((p, var))
            else:
                checks.append((p, value))
        if not free:
            row = [None] * len(self.pattern)
            for p, value in checks:
                row[p] = value
            if tuple(row) in rel.rows:
                yield bindings
            return
        last = len(self.pattern) - 1
        if self.exclusive and len(free) == 1 and free[0][0] == last and rel.by_key is not None:
            key = [None] * last
            for p, value in checks:
                key[p] = value
            found = rel.by_key.get(tuple(key))
            rows: Any = () if found is None else (found,)
        elif checks:
            rows = None
            for p, value in checks:
                bucket = rel.bucket(p, value)
                if rows is None or len(bucket) < len(rows):
                    rows = bucket
        else:
            rows = self.candidates(rel, bindings, ranges)
        if len(free) == 1:
            position, var = free[0]
            for row in rows:
                for p, value in checks:
                    if row[p] != value:
                        break
                else:
                    extended = bindings.copy()
                    extended[var] = row[position]
                    yield extended
            return
        for row in rows:
            if all(row[p] == value for p, value in checks):
                extended = bindings.copy()
                for p, var in free:
                    extended[var] = row[p]
                yield extended


@dataclass(frozen=True, slots=True)
class ComparisonStep:
    """``left op right``; ``=`` can bind a variable, the others need both sides bound."""

    op: str
    left: Any
    right: Any
    vars: frozenset

    def ready(self, bound: set) -> bool:
        if self.op != "=":
            return self.vars <= bound
        left_vars = set(variables(self.left))
        right_vars = set(variables(self.right))
        return left_vars <= bound or right_vars <= bound

    def solve(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        left = substitute(self.left, bindings)
        right = substitute(self.right, bindings)
        if self.op == "=":
            extended = dict(bindings)
            if is_ground(right) and match(left, right, extended) or is_ground(left) and match(right, left, extended):
                yield extended
            return
        if not (is_ground(left) and is_ground(right)):
            return
        if self.op == "!=":
            if not match(left, right, {}):
                yield bindings
            return
        if is_number(left) and is_number(right) and _NUMERIC_OPS[self.op](left, right):
            yield bindings


@dataclass(frozen=True, slots=True)
class BelongStep:
    """``belong(x, list)``: x is an element of the list; enumerates x when unbound."""

    element: Any
    collection: Any
    vars: frozenset

    @property
    def needs(self) -> frozenset:
        return frozenset(variables(self.collection))

    def ready(self, bound: set) -> bool:
        return self.needs <= bound

    def solve(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        collection = substitute(self.collection, bindings)
        if not isinstance(collection, tuple) or type(collection) is Struct:
            return
        element = substitute(self.element, bindings)
        for item in collection:
            extended = dict(bindings)
            if match(element, item, extended):
                yield extended


class ComputedStep:
    """A predicate answered by a Python function: the first ``inputs`` arguments must be bound.

    The function gets the input values and returns ``None``/``False`` for no solution;
    with no outputs, a true value for success; with one output, its value; with several,
    a tuple of them.
    """

    __slots__ = ("function", "goal", "inputs", "needs", "vars")

    def __init__(self, goal: Struct, function: Callable, inputs: int) -> None:
        self.goal = goal
        self.function = function
        self.inputs = inputs
        self.vars = frozenset(variables(goal))
        self.needs = frozenset(v for a in goal.args[:inputs] for v in variables(a))

    def ready(self, bound: set) -> bool:
        return self.needs <= bound

    def solve(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        args = [substitute(a, bindings) for a in self.goal.args]
        if not all(is_ground(a) for a in args[: self.inputs]):
            return
        try:
            result = self.function(*args[: self.inputs])
        except Exception:  # a broken computed predicate fails its goal, never the engine
            log.exception("computed predicate %s failed", self.goal.name)
            return
        outputs = len(args) - self.inputs
        if result is None or result is False:
            return
        if outputs == 0:
            yield bindings
            return
        values = (result,) if outputs == 1 else tuple(result)
        if len(values) != outputs:
            log.error("computed predicate %s returned %r", self.goal.name, result)
            return
        extended = dict(bindings)
        if all(match(p, from_python(v), extended) for p, v in zip(args[self.inputs:], values, strict=True)):
            yield extended


class NegationStep:
    """``not(...)``: succeeds when its body has no solution under the current bindings."""

    __slots__ = ("needs", "query", "vars")

    def __init__(self, query: Any, outer_vars: frozenset) -> None:
        self.query = query
        self.vars = query.vars
        self.needs = self.vars & outer_vars

    def ready(self, bound: set) -> bool:
        return self.needs <= bound

    def solve(self, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
        for _ in self.query.solutions(relations, bindings, first=True):
            return
        yield bindings


class _Unknown:
    pass


_UNKNOWN = _Unknown()
NUMERIC_ORDER_OPS = frozenset(_NUMERIC_OPS)
__all__ = ["BelongStep", "ComparisonStep", "ComputedStep", "FactStep", "NegationStep"]
