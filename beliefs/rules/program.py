"""Checking rules and putting them in strata: safety, clashes, termination, stratified negation.

A set of rules is accepted when every rule is range-restricted (each variable of its head, of a comparison
and of a negation is bound by a positive goal), no rule derives a stored, computed or built-in predicate, no
recursive rule builds new values (so evaluation always ends), and no predicate depends on its own negation.
:func:`stratify` returns the strata, lowest first: each is one strongly connected component of the
dependency graph, evaluated once the strata it reads are complete.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from aeroexec.beliefs.errors import RuleProblem
from aeroexec.beliefs.expression import BUILTIN_PREDICATES, Comparison, Conjunction, Goal, Negation, Rule
from aeroexec.beliefs.terms import Var, is_ground, variables

Signature = tuple[str, int]


@dataclass
class Stratum:
    """The rules of predicates that depend on each other (one strongly connected component), lowest first."""

    index: int
    predicates: tuple[Signature, ...]
    rules: list[Rule]
    #: every predicate its rules read, and those read under not(...)
    reads: set[Signature] = field(default_factory=set)
    negated: set[Signature] = field(default_factory=set)
    recursive: bool = False
    #: reads a computed predicate (a distance, a sensor): its answers are found again every time it is asked
    volatile: bool = False


@dataclass
class Vocabulary:
    """What the rules are checked against: the stored predicates declared (name -> arity), the computed ones, and
    whether an undeclared predicate is an error."""

    stored: Mapping[str, int]
    computed: Mapping[Signature, int]  # a computed predicate -> how many of its first arguments are its inputs
    closed: bool = False  # a vocabulary is declared: an unknown predicate is an error


def check(rules: list[Rule], vocabulary: Vocabulary) -> list[RuleProblem]:
    """Every problem of ``rules`` taken together (empty when they can be evaluated)."""
    problems: list[RuleProblem] = []
    computed = dict(vocabulary.computed)
    computed.update(dict.fromkeys(BUILTIN_PREDICATES, 0))
    arities: dict[str, Rule] = {}
    for rule in rules:
        if not rule.body.literals:
            continue
        name, arity = rule.head.signature
        first = arities.setdefault(name, rule)
        if first.head.arity != arity:
            problems.append(_problem(rule, f"{name} is derived with {first.head.arity} argument"
                                           f"{'s' if first.head.arity != 1 else ''} at {first.where}, "
                                           f"here with {arity}"))
        elif (name, arity) in computed or name == "not":
            problems.append(_problem(rule, f"the rule {rule} derives {name}, which is computed by the engine: "
                                           "a rule cannot derive it"))
        elif name in vocabulary.stored:
            declared = vocabulary.stored[name]
            if declared != arity:
                problems.append(_problem(rule, f"the rule {rule} derives {name}/{arity}, which clashes with the "
                                               f"stored predicate {name}/{declared}"))
            else:
                problems.append(_problem(rule, f"the rule {rule} derives {name}, which clashes with the stored "
                                               f"predicate {name}: a predicate is stored or derived"))
    derived = {r.head.signature for r in rules if r.body.literals}
    for rule in rules:
        if not rule.body.literals:
            if not is_ground(rule.head):
                problems.append(_problem(rule, f"the fact {rule} holds variables: a fact is ground"))
            elif rule.head.signature in computed:
                problems.append(_problem(rule, f"the fact {rule} names {rule.head.name}, which is computed by the "
                                               "engine: it cannot be stored"))
            elif vocabulary.stored.get(rule.head.name, rule.head.arity) != rule.head.arity:
                takes = vocabulary.stored[rule.head.name]
                problems.append(_problem(rule, f"The predicate {rule.head.name}/{rule.head.arity} of the fact {rule} "
                                               f"does not exist ({rule.head.name} takes {takes} argument"
                                               f"{'s' if takes != 1 else ''})"))
            continue
        problems.extend(_unknown(rule, derived, computed, vocabulary))
        problems.extend(_unsafe(rule, computed))
    return problems


def stratify(rules: list[Rule], computed: Mapping[Signature, int]) -> tuple[list[Stratum], list[RuleProblem]]:
    """The strata of ``rules`` (with a body), lowest first, or the negations that cannot be stratified."""
    computed = dict(computed)
    computed.update(dict.fromkeys(BUILTIN_PREDICATES, 0))
    by_head: dict[Signature, list[Rule]] = {}
    for rule in rules:
        if rule.body.literals:
            by_head.setdefault(rule.head.signature, []).append(rule)
    edges: dict[Signature, dict[Signature, tuple[bool, Rule]]] = {p: {} for p in by_head}
    for head, group in by_head.items():
        for rule in group:
            for signature, negative in _dependencies(rule.body, False):
                if signature in by_head:
                    known = edges[head].get(signature)
                    if known is None or (negative and not known[0]):
                        edges[head][signature] = (negative, rule)
    components = _components(list(by_head), {p: list(e) for p, e in edges.items()})
    problems: list[RuleProblem] = []
    strata: list[Stratum] = []
    for members in components:
        inside = set(members)
        for head in members:
            for target, (negative, rule) in edges[head].items():
                if negative and target in inside:
                    cycle = _cycle(target, head, edges, inside)
                    shown = " -> ".join(f"{a[0]}" if not n else f"not {a[0]}" for a, n in cycle)
                    problems.append(_problem(rule, f"the negation in {rule} cannot be stratified: {head[0]} depends "
                                                   f"on its own negation ({head[0]} -> {shown})"))
        group = [r for p in members for r in by_head[p]]
        stratum = Stratum(len(strata), tuple(sorted(members)), group)
        for rule in group:
            for signature, negative in _dependencies(rule.body, False):
                stratum.reads.add(signature)
                if negative:
                    stratum.negated.add(signature)
                if signature in computed and signature not in BUILTIN_PREDICATES:
                    stratum.volatile = True
        stratum.recursive = bool(stratum.reads & inside)
        problems.extend(_endless(stratum, computed))
        strata.append(stratum)
    volatile = {p for s in strata if s.volatile for p in s.predicates}
    for stratum in strata:  # reading a volatile predicate makes a stratum volatile
        if stratum.reads & volatile:
            stratum.volatile = True
            volatile.update(stratum.predicates)
    return strata, problems


# -- the checks ---------------------------------------------------------------------------------------------------
def _problem(rule: Rule, message: str) -> RuleProblem:
    return RuleProblem(message, rule.file, rule.line)


def _dependencies(body: Conjunction, negative: bool) -> Iterable[tuple[Signature, bool]]:
    for lit in body.literals:
        if type(lit) is Goal:
            if lit.term.signature not in BUILTIN_PREDICATES:
                yield lit.term.signature, negative
        elif type(lit) is Negation:
            yield from _dependencies(lit.body, True)


def _unknown(rule: Rule, derived: set[Signature], computed: Mapping[Signature, int],
             vocabulary: Vocabulary) -> Iterable[RuleProblem]:
    for (name, arity), _ in _dependencies(rule.body, False):
        if (name, arity) in derived or (name, arity) in computed:
            continue
        declared = vocabulary.stored.get(name)
        other = next((a for n, a in derived if n == name), None)
        if declared is None and other is None:
            if vocabulary.closed:
                yield _problem(rule, f"The predicate {name} of the rule {rule} does not exist")
        elif (declared if declared is not None else other) != arity:
            takes = declared if declared is not None else other
            yield _problem(rule, f"The predicate {name}/{arity} of the rule {rule} does not exist ({name} takes "
                                 f"{takes} argument{'s' if takes != 1 else ''})")


def _bound(literals: tuple, computed: Mapping[Signature, int]) -> tuple[set[Var], set[Var]]:
    """The variables a conjunction binds (positive goals, computed outputs, belong, =), and of those the ones
    bound to values found in beliefs (never built by a computed predicate or by = from a new term)."""
    bound: set[Var] = set()
    found: set[Var] = set()
    changed = True
    while changed:
        changed = False
        for lit in literals:
            new: set[Var] = set()
            from_beliefs = False
            if type(lit) is Goal:
                term = lit.term
                signature = term.signature
                if signature in computed:
                    if signature in BUILTIN_PREDICATES:
                        if term.name == "belong" and set(variables(term.args[1])) <= bound:
                            new = set(variables(term.args[0]))
                            from_beliefs = set(variables(term.args[1])) <= found
                    elif {v for a in term.args[:computed[signature]] for v in variables(a)} <= bound:
                        new = {v for a in term.args[computed[signature]:] for v in variables(a)}
                else:
                    new, from_beliefs = set(variables(term)), True
            elif type(lit) is Comparison and lit.op == "=":
                left, right = set(variables(lit.left)), set(variables(lit.right))
                for known, other, side in ((left, right, lit.right), (right, left, lit.left)):
                    if known <= bound and not other <= bound:
                        new = other
                        # ?Y = ?X or ?Y = constant copies a value; ?Y = (?X, 1) builds a new one
                        term_side = lit.left if side is lit.right else lit.right
                        from_beliefs = known <= found and (type(term_side) is Var or is_ground(term_side))
            if new - bound:
                bound |= new
                changed = True
            if from_beliefs and new - found:
                found |= new
                changed = True
    return bound, found


def _unsafe(rule: Rule, computed: Mapping[Signature, int]) -> Iterable[RuleProblem]:
    literals = rule.body.literals
    bound, _ = _bound(literals, computed)
    places: dict[Var, list[str]] = {}
    for v in variables(rule.head):
        places.setdefault(v, []).append("the head")
    for lit in literals:
        if type(lit) is Comparison:
            for v in [*variables(lit.left), *variables(lit.right)]:
                places.setdefault(v, []).append("a comparison")
        elif type(lit) is Negation:
            for inner in lit.body.literals:
                for v in _literal_vars(inner):
                    if not v.anonymous:
                        places.setdefault(v, []).append("a negation")
        elif lit.term.signature in computed:
            for v in variables(lit.term):
                places.setdefault(v, []).append(f"{lit.term.name}")
    for var in sorted(places, key=str):
        if var in bound:
            continue
        where = " and ".join(dict.fromkeys(places[var]))
        yield _problem(rule, f"The rule {rule} is not safe: {var} appears only in {where}, never in a goal that "
                             f"binds it")


def _literal_vars(lit) -> list[Var]:
    if type(lit) is Goal:
        return list(variables(lit.term))
    if type(lit) is Comparison:
        return [*variables(lit.left), *variables(lit.right)]
    return [v for inner in lit.body.literals for v in _literal_vars(inner)]


def _endless(stratum: Stratum, computed: Mapping[Signature, int]) -> Iterable[RuleProblem]:
    """Recursive rules that build new values (a computed value, a new term in the head) could derive without end."""
    inside = set(stratum.predicates)
    for rule in stratum.rules:
        if not any(s in inside for s, negative in _dependencies(rule.body, False) if not negative):
            continue
        _, found = _bound(rule.body.literals, computed)
        for arg in rule.head.args:
            if type(arg) is Var and arg not in found:
                yield _problem(rule, f"The recursive rule {rule} could derive beliefs without end: {arg} is "
                                     "computed, not found in a belief")
            elif type(arg) is not Var and not is_ground(arg):
                yield _problem(rule, f"The recursive rule {rule} could derive beliefs without end: its head builds "
                                     f"the new term {arg}")


def _components(nodes: list[Signature], edges: dict[Signature, list[Signature]]) -> list[list[Signature]]:
    """Tarjan's strongly connected components, each after every component it reaches (iterative)."""
    index: dict[Signature, int] = {}
    low: dict[Signature, int] = {}
    stack: list[Signature] = []
    on_stack: set[Signature] = set()
    out: list[list[Signature]] = []
    counter = 0
    for root in sorted(nodes):
        if root in index:
            continue
        work = [(root, iter(sorted(edges.get(root, ()))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    out.append(component)
    return out


def _cycle(start: Signature, end: Signature, edges: dict, inside: set[Signature]) -> list[tuple[Signature, bool]]:
    """A path from ``start`` to ``end`` inside a component, as (predicate, reached through a negation) pairs,
    beginning with ``start`` reached through the negation that closes the cycle."""
    previous: dict[Signature, tuple[Signature, bool] | None] = {start: None}
    queue = [start]
    while queue and end not in previous:
        node = queue.pop(0)
        for target, (negative, _) in sorted(edges[node].items()):
            if target in inside and target not in previous:
                previous[target] = (node, negative)
                queue.append(target)
    path: list[tuple[Signature, bool]] = []
    node = end
    while node != start and node in previous and previous[node] is not None:
        before, negative = previous[node]
        path.append((node, negative))
        node = before
    path.reverse()
    return [(start, True), *path]


__all__ = ["Stratum", "Vocabulary", "check", "stratify"]
