"""Set-at-a-time evaluation of a rule's body: every unification at once, as rows of values.

Where a query (``beliefs/query.py``) looks for unifications one at a time, a rule's body is evaluated for
all of them together: the partial answers are tuples of values (one per variable bound so far), grouped by
the values a goal shares with them and joined through the relation's index, the products built by
``itertools`` at C speed. Goals with nested terms, computed predicates, ``belong`` and ``=`` that binds are
solved answer by answer with the query's own steps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from itertools import product, starmap
from operator import add, itemgetter
from typing import Any

from aeroexec.beliefs.errors import EvaluationRefused
from aeroexec.beliefs.expression import Rule
from aeroexec.beliefs.query import CompiledQuery
from aeroexec.beliefs.relation import is_number
from aeroexec.beliefs.rules.budget import MAX_ROWS, Budget, refused
from aeroexec.beliefs.steps import ComparisonStep, FactStep, NegationStep
from aeroexec.beliefs.terms import Struct, Var, is_ground, match, substitute, variables

Rows = list[tuple]
#: Most memory the partial answers of one rule's body may take, estimated before they are built (a row of N values
#: is a tuple of about ROW_BYTES + 8 * N bytes, and its place in a list)
MAX_ANSWER_BYTES = 256 * 1024 * 1024
ROW_BYTES = 64
#: Work units of a goal solved answer by answer (its own query's steps), per row tried and per answer found
#: (twice each: a row in and a row out); and of one rule evaluated
EACH_COST = 8
CALL_COST = 40


_ORDER: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b, ">": lambda a, b: a > b, "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b,
}


def evaluate(query: CompiledQuery, relations: Any, rule: Rule, budget: Budget | None = None,
             named: Rule | None = None, lead: tuple[str, int] | None = None) -> Iterable[tuple]:
    """The arguments of the rule's head for every unification of ``query`` (its body; duplicates possible).

    ``lead``: the relation of the round's new rows (semi-naive evaluation), joined first: the other relations'
    columns are then built once and serve every round, where joining the new rows second would index them anew in
    each round.

    Raises :class:`EvaluationRefused` (naming the rule's file:line) before building partial answers that would
    take more than :data:`MAX_ANSWER_BYTES` (a join of goals that share no variable, over many beliefs: their
    size is estimated from the relations' sizes first), or more work than ``budget`` has left.
    """
    budget = budget or Budget()
    rule, head = named or rule, rule.head  # named: the rule a refusal names (the one written, for an internal one)
    budget.charge(CALL_COST, rule)
    schema: list[Var] = []
    rows: Rows = [()]
    order = query.plan(relations, {})
    if lead is not None and order and not (type(order[0]) is FactStep and order[0].signature == lead):
        first = next((s for s in order if type(s) is FactStep and s.signature == lead and s.flat), None)
        if first is not None:  # the others keep their order: a filter still comes after its variables are bound
            order = [first, *(s for s in order if s is not first)]
    args = head.args
    # the head's arguments distinct variables: the last join may build them directly (no row of every value first)
    wanted = args if args and all(type(a) is Var for a in args) else None
    if wanted is not None and budget.work is None and len(order) > 1:
        heads = _chain(query, order, wanted, relations)
        if heads is not None:
            budget.charge(len(heads), rule)
            return heads
    try:
        for n, step in enumerate(order):
            fits = _fits(len(schema) + 4)  # the rows its memory allows, a few new values each
            limit = min(budget.left(), fits)
            if wanted is not None and n == len(order) - 1 and type(step) is FactStep and step.flat:
                before = len(rows)
                heads = _join(step, schema, rows, relations, limit, wanted)
                if heads is not None:
                    budget.charge(len(heads) + before, rule)
                    return heads
            schema, rows, cost = _apply(step, schema, rows, relations, query.ranges, limit)
            budget.charge(cost, rule)
            if not rows:
                return ()
    except _Overflow as overflow:
        if budget.work is None or fits <= budget.left():  # the memory bound, not the work, was the nearer
            width = len(schema) + 4
            raise EvaluationRefused(
                f"the rule {rule} would build about {overflow.rows:,} partial answers (about "
                f"{overflow.rows * (ROW_BYTES + 8 * width) // 2 ** 20:,} MiB), more than the limit of "
                f"{MAX_ANSWER_BYTES // 2 ** 20} MiB (goals that share no variable?): refused before building them",
                rule.file, rule.line) from None
        raise refused(rule, budget) from None
    return _project(head, schema, rows)


def _fits(width: int) -> int:
    """Most rows of ``width`` values that fit in :data:`MAX_ANSWER_BYTES`."""
    return min(MAX_ROWS, MAX_ANSWER_BYTES // (ROW_BYTES + 8 * width))


class _Overflow(Exception):
    """The partial answers of a step would pass the rows it may build (``rows``: how many it would, at least)."""

    def __init__(self, rows: int) -> None:
        super().__init__(rows)
        self.rows = rows


def _apply(step: Any, schema: list[Var], rows: Rows, relations: Any, ranges: dict,
           limit: int) -> tuple[list[Var], Rows, int]:
    """The step applied to every row: the new schema, the new rows, and the work it took."""
    kind = type(step)
    if kind is FactStep and step.flat:
        before = len(rows)
        schema, rows = _join(step, schema, rows, relations, limit)
        return schema, rows, len(rows) + before  # each row grouped or tested, each answer built
    if kind is ComparisonStep and step.op != "=":
        test = _filter(step, schema)
        if test is not None:
            return schema, [row for row in rows if test(row)], len(rows)
    if kind is NegationStep:
        absent = _anti(step, schema, relations)
        if absent is not None:
            return schema, [row for row in rows if absent(row)], len(rows)
    before = len(rows)
    schema, rows = _each(step, schema, rows, relations, ranges, limit)
    return schema, rows, (len(rows) + before) * EACH_COST // 2


def _join(step: FactStep, schema: list[Var], rows: Rows, relations: Any, limit: int,
          wanted: tuple | None = None) -> Any:
    """The rows extended by the goal's answers (the new schema and rows); with ``wanted`` (a head's variables),
    the head rows themselves when the goal can build them in one pass, else None."""
    rel = relations.get(step.signature)
    if rel is None or not rel.rows:
        return [] if wanted is not None else (schema, [])
    at = {v: i for i, v in enumerate(schema)}
    shared = [(p, at[v]) for p, v in step.simple if v in at]
    fresh = [(p, v) for p, v in step.simple if v not in at]
    constants = step.constants
    if wanted is not None and (not shared or not fresh or len(shared) > 1 or constants):
        return None  # not a one-pass shape: the caller joins, then projects
    new_schema = schema + [v for _, v in fresh]
    positions = [p for p, _ in fresh]
    take = _getter(positions)
    whole = positions == list(range(len(step.pattern)))  # the rows as they are
    if not shared:  # no value in common: the goal's own answers, times every row so far
        candidates = _matching(rel, constants)
        if len(rows) * len(candidates) > limit:  # estimated from the sizes, before anything is built
            raise _Overflow(len(rows) * len(candidates))
        found = list(candidates) if whole else list(map(take, candidates))
        if rows == [()]:
            return new_schema, found
        return new_schema, list(starmap(add, product(rows, found)))
    if not fresh:  # every argument known: a membership test per row
        positions = sorted([*((p, None, c) for p, c in constants), *((p, i, None) for p, i in shared)])
        stored = rel.rows
        if len(positions) == 1:
            i = positions[0][1]
            return schema, [row for row in rows if (row[i],) in stored]
        build = _builder(positions)
        return schema, [row for row in rows if build(row) in stored]
    if len(shared) == 1 and not constants:
        p0, i = shared[0]
        taken = tuple(positions)
        # a value in common: each row extended by the stored values that go with its own, read from the relation's
        # columns (built once for a relation that does not change, or when building costs no more than the rows)
        if rel.columns_ready(p0, taken) or len(rel.rows) <= 4 * len(rows):
            table, widest = rel.columns(p0, taken)
            get = table.get
            if len(rows) * widest > limit:  # estimated before anything is built
                size = sum(len(get(row[i], ())) for row in rows)
                if size > limit:
                    raise _Overflow(size)
            if wanted is not None:
                if any(v not in at and v not in new_schema for v in wanted):
                    return None
                return _heads(tuple(("r", at[v]) if v in at else ("f", new_schema.index(v) - len(schema))
                                    for v in wanted), i)(rows, get)
            return new_schema, [row + f for row in rows for f in get(row[i], ())]
    if wanted is not None:
        return None
    groups: dict[Any, list[tuple]] = {}
    if len(shared) == 1:
        i = shared[0][1]
        for row in rows:
            value = row[i]
            group = groups.get(value)
            if group is None:
                groups[value] = [row]
            else:
                group.append(row)
    else:
        key = itemgetter(*(i for _, i in shared))
        for row in rows:
            groups.setdefault(key(row), []).append(row)
    out: Rows = []
    extend = out.extend
    p0 = shared[0][0]
    index = rel.by_pos[p0]
    others = [(p, j) for j, (p, _) in enumerate(shared)][1:]
    for value, group in groups.items():
        bucket = index.get(value if len(shared) == 1 else value[0])
        if bucket is None:
            continue
        if type(bucket) is not dict:
            bucket = (bucket,)
        if constants or others:
            bucket = [r for r in bucket if all(r[p] == c for p, c in constants)
                      and all(r[p] == value[j] for p, j in others)]
            if not bucket:
                continue
        if len(out) + len(group) * len(bucket) > limit:  # estimated before the group's answers are built
            raise _Overflow(len(out) + len(group) * len(bucket))
        found = list(bucket) if whole else list(map(take, bucket))
        if len(group) == 1:
            first = group[0]
            extend([first + f for f in found])
        else:
            extend(starmap(add, product(group, found)))
    return new_schema, out


_HEADS: dict[tuple, Callable] = {}


def _heads(sources: tuple[tuple[str, int], ...], i: int) -> Callable[[Rows, Callable], Rows]:
    """A comprehension building head rows from each row ``r`` and each stored part ``f`` that goes with its value at
    ``i`` (``sources``: where each head argument is, ``("r", k)`` or ``("f", k)``), compiled once per shape."""
    key = (sources, i)
    found = _HEADS.get(key)
    if found is None:
        items = ", ".join(f"{side}[{k}]" for side, k in sources) + ("," if len(sources) == 1 else "")
        found = eval(f"lambda rows, get: [({items}) for r in rows for f in get(r[{i}], ())]")  # noqa: S307
        _HEADS[key] = found
    return found


def _chain(query: CompiledQuery, order: list, wanted: tuple, relations: Any) -> Rows | None:
    """The head rows of a body that is a chain of stored goals, each after the first sharing one variable with those
    before it (``sg(?X, ?Y) :- sg#delta(?A, ?B), par(?X, ?A), par(?Y, ?B)``), built in one nested comprehension
    compiled per shape, with no partial answer as a row: None for any other body, or when the answers could pass
    what one evaluation may build (then the caller joins step by step, with its bounds)."""
    shapes = query.__dict__.setdefault("chains", {})  # by its steps' order (they live as long as the query)
    key = (*map(id, order), wanted)
    shape = shapes.get(key)
    if shape is None:
        shape = shapes[key] = _chain_shape(order, wanted)
    if shape is False:
        return None
    build, joins = shape
    rel = relations.get(order[0].signature)
    if rel is None or not rel.rows:
        return []
    estimate = len(rel.rows)
    gets = []
    for signature, p0, taken in joins:
        other = relations.get(signature)
        if other is None or not other.rows:
            return []
        if not other.columns_ready(p0, taken) and len(other.rows) > 4 * len(rel.rows):
            return None  # building its columns would cost more than the rows joined
        table, widest = other.columns(p0, taken)
        estimate *= max(widest, 1)
        gets.append(table.get)
    if estimate > _fits(len(wanted) + 4):
        return None
    return build(rel.rows, *gets)


def _chain_shape(order: list, wanted: tuple) -> Any:
    """For :func:`_chain`: the comprehension and, per join, (the relation, the shared place, the places taken);
    False when the body is not such a chain."""
    if any(type(step) is not FactStep or not step.flat or step.constants for step in order):
        return False
    where: dict[Var, str] = {v: f"r[{p}]" for p, v in order[0].simple}
    loops, joins = [], []
    for k, step in enumerate(order[1:], 1):
        shared = [(p, v) for p, v in step.simple if v in where]
        fresh = [(p, v) for p, v in step.simple if v not in where]
        if len(shared) != 1 or not fresh:
            return False
        p0, var = shared[0]
        joins.append((step.signature, p0, tuple(p for p, _ in fresh)))
        loops.append(f"for f{k} in g{k}({where[var]}, ())")
        for t, (_, v) in enumerate(fresh):
            where[v] = f"f{k}[{t}]"
    if any(v not in where for v in wanted):
        return False
    items = ", ".join(where[v] for v in wanted) + ("," if len(wanted) == 1 else "")
    names = ", ".join(f"g{k}" for k in range(1, len(order)))
    build = eval(f"lambda rows, {names}: [({items}) for r in rows {' '.join(loops)}]")  # noqa: S307
    return build, joins


def _matching(rel: Any, constants: tuple) -> Iterable[tuple]:
    if not constants:
        return rel.rows
    rows = min((rel.bucket(p, c) for p, c in constants), key=len)
    if len(constants) == 1:
        return rows
    return [r for r in rows if all(r[p] == c for p, c in constants)]


def _getter(positions: list[int]) -> Callable[[tuple], tuple]:
    if not positions:
        return lambda row: ()
    if len(positions) == 1:
        p = positions[0]
        return lambda row: (row[p],)
    return itemgetter(*positions)


def _builder(positions: list[tuple[int, int | None, Any]]) -> Callable[[tuple], tuple]:
    """A function from a row of answers to the stored row a goal asks for (positions: (place, column, constant)).

    A goal without arguments (``d1``) asks for the empty row."""
    if not positions:
        return lambda row: ()
    if len(positions) == 1 and positions[0][1] is not None:
        i = positions[0][1]
        return lambda row: (row[i],)
    if all(i is not None for _, i, _ in positions):
        return itemgetter(*(i for _, i, _ in positions))
    parts = [(i, c) for _, i, c in positions]
    return lambda row: tuple(c if i is None else row[i] for i, c in parts)


def _filter(step: ComparisonStep, schema: list[Var]) -> Callable[[tuple], bool] | None:
    at = {v: i for i, v in enumerate(schema)}
    sides = []
    for side in (step.left, step.right):
        if type(side) is Var and side in at:
            sides.append((at[side], None))
        elif type(side) is not Var and is_ground(side):
            sides.append((None, side))
        else:
            return None
    (li, lc), (ri, rc) = sides
    if step.op == "!=":
        def differ(row: tuple) -> bool:
            left = lc if li is None else row[li]
            right = rc if ri is None else row[ri]
            return not match(left, right, {})
        return differ
    order = _ORDER[step.op]

    def holds(row: tuple) -> bool:
        left = lc if li is None else row[li]
        right = rc if ri is None else row[ri]
        return is_number(left) and is_number(right) and order(left, right)
    return holds


def _anti(step: NegationStep, schema: list[Var], relations: Any) -> Callable[[tuple], bool] | None:
    """``not(goal)`` with every argument known: a membership test (None when the negation is not that simple)."""
    inner = step.query.steps
    if len(inner) != 1 or type(inner[0]) is not FactStep or not inner[0].flat:
        return None
    goal = inner[0]
    at = {v: i for i, v in enumerate(schema)}
    if any(v not in at for _, v in goal.simple):
        return None
    rel = relations.get(goal.signature)
    if rel is None:
        return lambda row: True
    stored = rel.rows
    positions = sorted([*((p, None, c) for p, c in goal.constants), *((p, at[v], None) for p, v in goal.simple)])
    if len(positions) == 1 and positions[0][1] is not None:
        i = positions[0][1]
        return lambda row: (row[i],) not in stored
    build = _builder(positions)
    return lambda row: build(row) not in stored


def _each(step: Any, schema: list[Var], rows: Rows, relations: Any, ranges: dict,
          limit: int) -> tuple[list[Var], Rows]:
    """Any step, answer by answer, through its own ``solve`` (nested terms, computed predicates, belong, =); each
    answer tried costs :data:`EACH_COST` of ``limit``."""
    known = set(schema)
    fresh = [v for v in dict.fromkeys(_step_vars(step)) if v not in known]
    new_schema = schema + fresh
    out: Rows = []
    if len(rows) * EACH_COST // 2 > limit:
        raise _Overflow(len(rows) * EACH_COST // 2)
    left = (limit - len(rows) * EACH_COST // 2) * 2 // EACH_COST
    for row in rows:
        bindings = dict(zip(schema, row, strict=True))
        for extended in step.solve(relations, bindings, ranges):
            if fresh:
                out.append(row + tuple(extended[v] for v in fresh))
            else:
                out.append(row)
            if len(out) > left:
                raise _Overflow((len(out) + len(rows)) * EACH_COST // 2)
    return new_schema, out


def _step_vars(step: Any) -> list[Var]:
    if type(step) is FactStep:
        return [v for a in step.pattern for v in variables(a)]
    if type(step) is NegationStep:
        return []
    return sorted(step.vars, key=str)


def _project(head: Struct, schema: list[Var], rows: Rows) -> Iterable[tuple]:
    at = {v: i for i, v in enumerate(schema)}
    args = head.args
    if all(type(a) is Var for a in args):
        if len(args) == 1:
            i = at[args[0]]
            return [(row[i],) for row in rows]
        if not args:
            return [()] if rows else []
        return map(itemgetter(*(at[a] for a in args)), rows)
    if all(type(a) is Var or is_ground(a) for a in args):
        return map(_builder([(p, at[a], None) if type(a) is Var else (p, None, a) for p, a in enumerate(args)]), rows)
    return [tuple(substitute(a, dict(zip(schema, row, strict=True))) for a in args) for row in rows]


__all__ = ["MAX_ANSWER_BYTES", "evaluate"]
