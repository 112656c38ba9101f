"""Property tests: the indexed, reordered evaluation finds exactly what a naive one finds."""

from aeroexec.beliefs import BeliefMemory, Struct, Var
from aeroexec.beliefs.expression import Comparison, Conjunction, Goal, Negation
from aeroexec.beliefs.terms import from_python
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from naive_evaluator import facts_of, solve

PREDICATES = {"p": 2, "q": 2, "r": 1, "s": 3, "m": 2}  # m is multi-valued
CONSTANTS = ["a", "b", "c", 0, 1, 2, 3, 2.5]
VARIABLES = [Var("?X"), Var("?Y"), Var("?Z")]

facts = st.lists(
    st.sampled_from(sorted(PREDICATES)).flatmap(
        lambda name: st.tuples(st.just(name), st.lists(
            st.one_of(st.sampled_from(CONSTANTS), st.tuples(st.sampled_from(CONSTANTS),
                                                             st.sampled_from(CONSTANTS))),
            min_size=PREDICATES[name], max_size=PREDICATES[name]))),
    max_size=40,
)


def argument(with_tuples=True):
    options = [st.sampled_from(CONSTANTS), st.sampled_from(VARIABLES)]
    if with_tuples:
        options.append(st.tuples(st.sampled_from(CONSTANTS + VARIABLES),
                                 st.sampled_from(CONSTANTS + VARIABLES)))
    return st.one_of(*options)


goal = st.sampled_from(sorted(PREDICATES)).flatmap(
    lambda name: st.lists(argument(), min_size=PREDICATES[name], max_size=PREDICATES[name]).map(
        lambda args: Goal(Struct(name, tuple(from_python(a) for a in args)))))


@st.composite
def conjunctions(draw):
    """Goals first, then filters on variables the goals bind (the naive order must be valid)."""
    goals = draw(st.lists(goal, min_size=1, max_size=4))
    bound = [v for g in goals for v in VARIABLES if v in _vars(g.term)]
    literals = list(goals)
    if bound:
        for _ in range(draw(st.integers(0, 2))):
            var = draw(st.sampled_from(bound))
            op = draw(st.sampled_from(["<", ">", "<=", ">=", "=", "!="]))
            literals.append(Comparison(op, var, draw(st.sampled_from(CONSTANTS))))
        if draw(st.booleans()):
            literals.append(Negation(Conjunction((draw(goal),))))
        if draw(st.booleans()):
            var = draw(st.sampled_from(bound))
            literals.append(Goal(Struct("belong", (var, from_python(["a", 1, 2.5])))))
    return Conjunction(tuple(literals))


def _vars(value):
    from aeroexec.beliefs.terms import variables
    return set(variables(value))


def _load(fact_list):
    memory = BeliefMemory(multivalued={"m"})
    for name, args in fact_list:
        memory.add(Struct(name, tuple(from_python(a) for a in args)))
    return memory


def _frozen(solution):
    return frozenset((k, repr(v)) for k, v in solution.items())


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(facts, conjunctions())
def test_same_solution_sets_as_left_to_right_backtracking(fact_list, conjunction):
    memory = _load(fact_list)
    stored = facts_of(memory)
    names = conjunction.variables
    expected = {
        frozenset((v.name, repr(_py(s[v]))) for v in names if v in s)
        for s in solve(list(conjunction.literals), stored)
    }
    found = {_frozen(s) for s in memory.query_all(conjunction)}
    assert found == expected
    first = memory.query(conjunction)
    assert (first is None) == (not expected)
    if first is not None:
        assert _frozen(first) in expected


@settings(max_examples=150, deadline=None)
@given(facts, st.lists(st.tuples(st.sampled_from(["add", "remove"]), facts), max_size=4),
       conjunctions())
def test_same_answers_after_adds_and_removes(fact_list, changes, conjunction):
    memory = _load(fact_list)
    memory.query_all(conjunction)  # plan and cache before the changes
    for kind, batch in changes:
        for name, args in batch:
            belief = Struct(name, tuple(from_python(a) for a in args))
            memory.add(belief) if kind == "add" else memory.remove(belief)
    expected = {
        frozenset((v.name, repr(_py(s[v]))) for v in conjunction.variables if v in s)
        for s in solve(list(conjunction.literals), facts_of(memory))
    }
    assert {_frozen(s) for s in memory.query_all(conjunction)} == expected


def _py(value):
    from aeroexec.beliefs.terms import to_python
    return to_python(value)
