"""A plain left-to-right backtracking evaluator over a list of facts: the tests' oracle."""

from aeroexec.beliefs.expression import Comparison, Goal, Negation
from aeroexec.beliefs.terms import Struct, is_ground, match, substitute


def solve(literals, facts, bindings=None):
    """Yield every unification of the literals, left to right, scanning every fact."""
    bindings = dict(bindings or {})
    if not literals:
        yield bindings
        return
    first, rest = literals[0], literals[1:]
    if type(first) is Goal:
        goal = first.term
        if goal.name == "belong" and len(goal.args) == 2:
            collection = substitute(goal.args[1], bindings)
            for item in collection:
                extended = dict(bindings)
                if match(substitute(goal.args[0], bindings), item, extended):
                    yield from solve(rest, facts, extended)
            return
        if goal.name in ("less_than", "greater_than") and len(goal.args) == 2:
            op = "<" if goal.name == "less_than" else ">"
            first = Comparison(op, goal.args[0], goal.args[1])
        else:
            for fact in facts:
                extended = dict(bindings)
                if match(goal, fact, extended):
                    yield from solve(rest, facts, extended)
            return
    if type(first) is Comparison:
        left, right = substitute(first.left, bindings), substitute(first.right, bindings)
        if first.op == "=":
            extended = dict(bindings)
            if is_ground(right) and match(left, right, extended):
                yield from solve(rest, facts, extended)
            return
        if not (is_ground(left) and is_ground(right)):
            return
        if first.op == "!=":
            if not match(left, right, {}):
                yield from solve(rest, facts, bindings)
            return
        numeric = all(type(v) in (int, float) for v in (left, right))
        ops = {"<": lambda a, b: a < b, ">": lambda a, b: a > b,
               "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b}
        if numeric and ops[first.op](left, right):
            yield from solve(rest, facts, bindings)
        return
    if type(first) is Negation:
        for _ in solve(list(first.body.literals), facts, bindings):
            return
        yield from solve(rest, facts, bindings)


def facts_of(memory):
    return [Struct(b.name, b.args) for b in memory]


def derive(rules, facts, level_of):
    """Every fact ``rules`` derive from ``facts`` (a list of :class:`Struct`), bottom-up and naively: level by level
    (``level_of``: a derived predicate's level; a rule negates only lower ones), each level's rules applied to
    everything known until nothing new comes."""
    known = list(facts)
    seen = set(known)
    for level in sorted(set(level_of.values())):
        group = [rule for rule in rules if level_of[rule.head.name] == level]
        changed = True
        while changed:
            changed = False
            for rule in group:
                for bindings in list(solve(list(rule.body.literals), known)):
                    fact = substitute(rule.head, bindings)
                    if fact not in seen:
                        seen.add(fact)
                        known.append(fact)
                        changed = True
    return known
