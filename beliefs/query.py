"""Compiled belief queries: plan the order of a conjunction's goals, then solve it.

The planner orders goals so that each step touches as few beliefs as the indexes
predict (not left to right): filters run as soon as their variables are bound,
and the stored goal with the smallest expected answer comes next. Plans are cached
until some relation of the memory doubles or halves in size (the memory's epoch). Asking for every
solution joins goals that share a single variable by intersecting cached sets at C speed, then puts
the answers in insertion order.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from itertools import chain

from aeroexec.beliefs.expression import Comparison, Conjunction, Goal, Negation, literal_variables
from aeroexec.beliefs.shared import SharedStep
from aeroexec.beliefs.steps import (
    NUMERIC_ORDER_OPS,
    BelongStep,
    ComparisonStep,
    ComputedStep,
    FactStep,
    NegationStep,
)
from aeroexec.beliefs.terms import Var, to_python, variables

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

_FLIP = {"<": ">", ">": "<", "<=": ">=", ">=": "<="}
_PLAIN = frozenset((str, int, float))


class _NoRows:
    rows: dict = {}  # noqa: RUF012 (never changed)


_NO_ROWS = _NoRows()


class CompiledQuery:
    """A conjunction compiled against a memory's vocabulary; reusable across calls."""

    def __init__(
        self,
        conjunction: Conjunction,
        exclusive: Callable[[str], bool],
        computed: dict,
        outer_vars: frozenset = frozenset(),
    ) -> None:
        self.text = conjunction.text or str(conjunction)
        self.names: tuple[Var, ...] = conjunction.variables
        literals = conjunction.literals
        all_vars = frozenset(v for lit in literals for v in literal_variables(lit))
        self.vars = all_vars
        self.steps: list = []
        for i, lit in enumerate(literals):
            others = frozenset(
                v for j, o in enumerate(literals) if j != i for v in literal_variables(o)
            )
            self.steps.append(_compile(lit, exclusive, computed, others | outer_vars))
        self.ranges = _ranges(self.steps)
        self.signatures = tuple({s.signature for s in self.steps if type(s) is FactStep})
        #: the stored predicates it reads (None: it reads a computed one); its last answer, and the sum of the
        #: relations' versions it was found at (the memory answers from it while that stands: ``BeliefMemory``)
        self.reads: tuple[tuple[str, int], ...] | None = None
        self.derived: tuple[tuple[str, int], ...] | None = None  # the derived predicates it reads
        self.answer: dict | None = None
        self.stamp = -1
        #: whether its answer changes only with the memory's ``version`` (no computed predicate, shared beliefs or
        #: beliefs that expire read, through the rules too): ``BeliefMemory.holds_standing``
        self.lasting = False
        self._plans: dict = {}
        only = self.steps[0] if len(self.steps) == 1 else None
        self._single = only if type(only) is FactStep and not only.nested else None
        # a single exclusive goal asking for its value, its key given: one dictionary look-up
        self._keyed = None
        if self._single is not None and only.exclusive and len(only.simple) == 1:
            position, var = only.simple[0]
            if position == len(only.pattern) - 1:
                self._keyed = (only.pattern[:-1], "" if var.anonymous else var.name)
        #: the first answer of a single stored goal, ground or asking for its value, in one look-up (the memory
        #: binds it to its relations: :meth:`probe_in`)
        self.probe: Callable[[], dict | None] | None = None

    def probe_in(self, relations: dict) -> Callable[[], dict | None] | None:
        """The first answer of a single stored goal, ground or asking for its value, in ``relations`` (a memory's,
        which never drops a relation it made): the relation is looked up until it exists, then kept, so an answer
        is one look-up in its index. None for any other query."""
        single = self._single
        if single is None or (single.simple and self._keyed is None):
            return None
        signature = single.signature
        rel: Any = None  # the relation, once it exists
        first: dict | None = None  # its first argument's index (a relation's indexes are never replaced)

        if not single.simple:
            pattern = single.pattern

            def holds() -> dict | None:
                nonlocal rel
                if rel is None:
                    rel = relations.get(signature)
                    if rel is None:
                        return None
                return {} if pattern in rel.rows else None
            return holds
        key, name = self._keyed
        # the key of a two-argument belief is its first argument: its index holds the one row with that value
        by_first, value_of = len(key) == 1, key[0]
        solve = self.first

        def value() -> dict | None:
            nonlocal rel, first
            if rel is None:
                rel = relations.get(signature)
                if rel is None:
                    return None
                first = rel.by_pos[0]
            if rel.by_key is None:  # declared multivalued since
                return solve(relations)
            row = first.get(value_of) if by_first else rel.by_key.get(key)
            if row is None:
                return None
            if not name:
                return {}
            answer = row[-1]
            kind = type(answer)
            return {name: answer if kind is str or kind is int or kind is float else to_python(answer)}
        return value

    # -- planning ---------------------------------------------------------------
    def plan(self, relations: dict, bindings: dict) -> list:
        """The steps in execution order for the current statistics of the memory."""
        epoch = relations.epoch
        key = (epoch, frozenset(bindings)) if bindings else epoch
        order = self._plans.get(key)
        if order is None:
            order = self._order(relations, bindings)
            if len(self._plans) > 64:
                self._plans.clear()
            self._plans[key] = order
        return order

    def _order(self, relations: dict, bindings: dict) -> list:
        bound = set(bindings)
        remaining = list(self.steps)
        order = []
        while remaining:
            pick = next(
                (s for s in remaining if type(s) is not FactStep and s.ready(bound)), None
            )
            if pick is None:
                best_cost = None
                for step in remaining:
                    if type(step) is FactStep:
                        cost = step.estimate(relations, bound, bindings, self.ranges)
                        if best_cost is None or cost < best_cost:
                            pick, best_cost = step, cost
            if pick is None:  # only steps whose variables never get bound: they fail
                return order + remaining
            order.append(pick)
            remaining.remove(pick)
            if type(pick) is not NegationStep:
                bound |= pick.vars
        return order

    # -- solving ----------------------------------------------------------------
    def solutions(self, relations: dict, bindings: dict, first: bool = False) -> Iterator[dict]:
        """Every unification (as Var -> value dicts) extending ``bindings``."""
        order = self.plan(relations, bindings)
        start = 0 if first else _star_length(order, bindings)
        if start < 2:
            return _dfs(order, 0, relations, bindings, self.ranges)
        return self._star(order, start, relations, bindings)

    def _star(self, order: list, length: int, relations: dict, bindings: dict) -> Iterator[dict]:
        var = order[0].simple[0][1]
        for value in _star_values(order, length, relations):
            extended = dict(bindings)
            extended[var] = value
            yield from _dfs(order, length, relations, extended, self.ranges)

    def first(self, relations: dict, bindings: dict | None = None) -> dict | None:
        """The first unification as ``{"?X": value}``, ``{}`` for a true ground query, or None."""
        single = self._single
        if single is not None and not bindings:
            rel = relations.get(single.signature)
            if rel is None:
                return None
            if not single.simple:
                return {} if single.pattern in rel.rows else None
            if self._keyed is not None and rel.by_key is not None:
                row = rel.by_key.get(self._keyed[0])
                if row is None:
                    return None
                name = self._keyed[1]
                return {name: to_python(row[-1])} if name else {}
        for solution in self.solutions(relations, bindings or {}, first=True):
            return self.result(solution)
        return None

    def all(self, relations: dict, bindings: dict | None = None) -> list[dict]:
        """Every unification, as ``{"?X": value}`` dictionaries."""
        bindings = bindings or {}
        order = self.plan(relations, bindings)
        var = order[0].simple[0][1] if order and type(order[0]) is FactStep and order[0].simple else None
        if var is not None and not var.anonymous and _star_length(order, bindings) == len(order) > 1 \
                and self.names == (var,):  # goals on one variable and nothing else: the values are the answers
            name = var.name
            values = _star_values(order, len(order), relations)
            if _PLAIN.issuperset(map(type, values)):  # names and numbers: each answer's dictionary as it is
                return [{name: value} for value in values]
            return [{name: to_python(value)} for value in values]
        return [self.result(s) for s in self.solutions(relations, bindings)]

    def count(self, relations: dict, bindings: dict | None = None) -> int:
        """How many unifications there are: the size of the relation for one goal of distinct variables."""
        if not bindings:
            whole = self._whole_relation(relations)
            if whole is not None:
                return len(whole.rows)
        bindings = bindings or {}
        order = self.plan(relations, bindings)
        if _star_length(order, bindings) == len(order) > 1:
            return len(_star_found(order, len(order), relations)[0])  # no order needed
        return sum(1 for _ in self.solutions(relations, bindings))

    def tuples(self, relations: dict, bindings: dict | None = None) -> Iterator[tuple]:
        """Every unification as a tuple of the values of :attr:`names` (taken now: a list's iterator)."""
        if not bindings:
            whole = self._whole_relation(relations)
            if whole is not None:
                rows = list(whole.rows)
                if _PLAIN.issuperset(map(type, chain.from_iterable(rows))):  # names and numbers: the rows as they are
                    return iter(rows)
                return iter([tuple(map(to_python, row)) for row in rows])
        names = self.names
        if len(names) == 1:
            name = names[0]
            found = [(to_python(s.get(name)),) for s in self.solutions(relations, bindings or {})]
        else:
            found = [tuple(to_python(s.get(v)) for v in names) for s in self.solutions(relations, bindings or {})]
        return iter(found)

    def _whole_relation(self, relations: dict) -> Any:
        """The relation this query reads whole (one goal, a distinct named variable at each place, in order), or
        None."""
        single = self._single
        if single is None or not single.flat or single.constants or len(single.simple) != len(single.pattern) \
                or self.names != single.pattern or any(v.anonymous for v in self.names):
            return None
        rel = relations.get(single.signature)
        return rel if rel is not None else _NO_ROWS

    def result(self, solution: dict) -> dict:
        return {v.name: to_python(solution[v]) for v in self.names if v in solution}


def _dfs(order: list, i: int, relations: dict, bindings: dict, ranges: dict) -> Iterator[dict]:
    if i == len(order):
        yield bindings
        return
    step = order[i]
    if i + 1 == len(order):
        yield from step.solve(relations, bindings, ranges)
        return
    if i + 2 == len(order):
        last = order[i + 1].solve
        for extended in step.solve(relations, bindings, ranges):
            yield from last(relations, extended, ranges)
        return
    for extended in step.solve(relations, bindings, ranges):
        yield from _dfs(order, i + 1, relations, extended, ranges)


def _star_values(order: list, length: int, relations: dict) -> list:
    """The values of the one variable the first ``length`` goals share, in insertion order: their cached value
    sets intersected at C speed (the smallest walked), then only the answers sorted, by their rank in the smallest
    goal's values."""
    found, rel, step = _star_found(order, length, relations)
    if rel is None:
        return []
    return sorted(found, key=rel.projection(step.constants, step.simple[0][0]).__getitem__)


def _star_found(order: list, length: int, relations: dict) -> tuple[frozenset, Any, Any]:
    """The set of values the first ``length`` goals share (in no order), and the goal with the fewest values (the
    first of them) with its relation, whose ranks order them (None, None when some goal's relation does not
    exist)."""
    sets = []
    for step in order[:length]:
        rel = relations.get(step.signature)
        if rel is None:
            return frozenset(), None, None
        sets.append((rel.projection_set(step.constants, step.simple[0][0]), rel, step))
    sets.sort(key=_size)  # stable: the first of the smallest
    smallest, rel, step = sets[0]
    return smallest.intersection(*[found for found, _, _ in sets[1:]]), rel, step


def _size(entry: tuple) -> int:
    return len(entry[0])


def _star_length(order: list, bindings: dict) -> int:
    """How many leading stored goals constrain one same unbound variable and nothing else."""
    var = None
    length = 0
    for step in order:
        if type(step) is not FactStep or step.nested or len(step.simple) != 1:
            break
        candidate = step.simple[0][1]
        if var is None:
            if candidate in bindings:
                break
            var = candidate
        elif candidate != var:
            break
        length += 1
    return length


def _compile(lit, exclusive: Callable[[str], bool], computed: dict, outer: frozenset):
    if type(lit) is Goal:
        goal = lit.term
        name, arity = goal.signature
        if (name, arity) in computed:
            function, inputs = computed[(name, arity)]
            if inputs is None:  # stored beliefs, then those several memories share (beliefs/shared.py)
                return SharedStep(goal, exclusive(name), function)
            return ComputedStep(goal, function, inputs)
        if name == "belong" and arity == 2:
            return BelongStep(goal.args[0], goal.args[1], frozenset(variables(goal)))
        if name in ("less_than", "greater_than") and arity == 2:
            op = "<" if name == "less_than" else ">"
            return ComparisonStep(op, goal.args[0], goal.args[1], frozenset(variables(goal)))
        return FactStep(goal, exclusive(name))
    if type(lit) is Comparison:
        vars_ = frozenset([*variables(lit.left), *variables(lit.right)])
        return ComparisonStep(lit.op, lit.left, lit.right, vars_)
    if type(lit) is Negation:
        inner = CompiledQuery(lit.body, exclusive, computed, outer)
        return NegationStep(inner, outer)
    raise TypeError(f"not a literal: {lit!r}")


def _ranges(steps: list) -> dict[Var, Any]:
    """Numeric bounds that comparisons with constants put on single variables."""
    ranges: dict[Var, Any] = {}
    for step in steps:
        if type(step) is not ComparisonStep or step.op not in NUMERIC_ORDER_OPS:
            continue
        op, left, right = step.op, step.left, step.right
        if type(right) is Var and type(left) in (int, float):
            op, left, right = _FLIP[op], right, left
        if type(left) is not Var or type(right) not in (int, float):
            continue
        low, high, (low_in, high_in) = ranges.get(left, (None, None, (True, True)))
        if op in (">", ">=") and (low is None or right >= low):
            low, low_in = right, op == ">="
        elif op in ("<", "<=") and (high is None or right <= high):
            high, high_in = right, op == "<="
        ranges[left] = (low, high, (low_in, high_in))
    return ranges


__all__ = ["CompiledQuery"]
