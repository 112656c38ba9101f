"""The belief language: every expression of the paper parses; bad text gets the paper's error."""

import pytest
from aeroexec.beliefs import (
    BeliefSyntaxError,
    Comparison,
    Goal,
    ListTerm,
    Negation,
    Struct,
    Var,
    format_term,
    parse_belief,
    parse_expression,
    parse_term,
)
from aeroexec.beliefs.grammar_reading import read_expression
from aeroexec.beliefs.parser import _read_flat
from hypothesis import given, settings
from hypothesis import strategies as st

from aeroexec.limits import MAX_LITERALS, MAX_TERM_DEPTH

# Every belief expression quoted in the paper: section 5.1, Tables 5-7, the
# catalog's reactive conditions (Figure 6, Appendix B), Table 8 and Figure 10.
PAPER_EXPRESSIONS = [
    # Table 5 and section 5.1
    "object(x, y)", "position(x, y)", "name(x, y)", "flight_state(x, y)", "code(x, y)",
    "color(x, y)", "frequency(communication, x)", "charge(battery, x)", "carry(self, x)",
    "image(x, y)", "temperature(air, x)", "visible(x)", "stability(ground, x)",
    "charge(battery, empty)", "charge(battery, full)", "communication(wireless, ok)",
    "charge_level(battery, ok)", "visibility(camera, ok)", "vibrations(self, none)",
    # Table 6, line by line and joined into whole preconditions
    "flight_state(self, ?x1), belong(?x1, [moving, hovering])",
    "position(self, ?x2), approximate_travel_time(?x2, ?y, ?t), ?t < 30",
    "minimum_distance_to_obstacle(?y, ?d), ?d > 3",
    "flight_state(self, ?x1), belong(?x1, [moving, hovering]), position(self, ?x2), "
    "approximate_travel_time(?x2, ?y, ?t), ?t < 30, minimum_distance_to_obstacle(?y, ?d), ?d > 3",
    "flight_state(self, ?x), belong(?x, [moving, hovering])",
    "position(self, ?x), minimum_distance_to_obstacle(?x, ?y), ?x > 3",
    "charge_level(battery, ?x), ?x > 30",
    "stability(ground, stable)",
    "flight_state(self, ?x), belong(?x, [moving, hovering]), stability(ground, stable)",
    # Table 7
    "belong(x, y)", "?x > ?y", "?x < ?y", "?x = ?y", "?x >= ?y", "?x <= ?y",
    "approximate_travel_time(x, y)", "distance_to_obstacle(x, y)",
    # reactive conditions (Figure 6, Appendix B)
    "flight_state(self, FLYING)",
    "charge(battery, ?X), less_than(?X, 10)",
    # Table 8 and Figure 10
    "charge(battery, ?X)",
    "object(?X, marker), code(?X, 3)",
    "position(self, (?x,?y,?z))",
    # issue examples
    "not(visible(marker_3))", "?X >= 2", "?X != 2", "greater_than(?X, 2)",
    "position(o1, (1.0, 2.5, -3))", "path(self, [[2.5, 3.2, 1.5], [1.2, 3.3, 1.5]])",
    "name(?P, 'Ann Smith')", "hovering", "x(?), ?X <= -2.5",
]


@pytest.mark.parametrize("text", PAPER_EXPRESSIONS)
def test_every_paper_expression_parses(text):
    expression = parse_expression(text)
    assert expression.literals
    # the printed form reads back to the same expression
    assert parse_expression(str(expression)) == expression


def test_parsed_structure():
    expr = parse_expression("object(?X, marker), code(?X, 3), ?X != o2, not(visible(?X))")
    goal, code, comparison, negation = expr.literals
    assert goal == Goal(Struct("object", (Var("?X"), "marker")))
    assert code.term.args == (Var("?X"), 3)
    assert comparison == Comparison("!=", Var("?X"), "o2")
    assert type(negation) is Negation and negation.body.literals[0].term.name == "visible"
    assert expr.predicates == {("object", 2), ("code", 2), ("visible", 1)}
    assert [v.name for v in expr.variables] == ["?X"]


def test_values_terms():
    assert parse_term("(1.0, 2.5, -3)") == (1.0, 2.5, -3)
    assert type(parse_term("[moving, hovering]")) is ListTerm
    assert parse_term("[[1, 2], (a, b)]") == ((1, 2), ("a", "b"))
    assert parse_term('"quoted text"') == "quoted text"
    assert parse_term("f(g(1), [x])") == Struct("f", (Struct("g", (1,)), ListTerm(["x"])))
    assert parse_term("-4") == -4 and parse_term("1e3") == 1000.0
    anonymous = parse_expression("p(?, ?)").literals[0].term.args
    assert anonymous[0] != anonymous[1]


def test_parse_is_cached():
    text = "charge(battery, ?X), ?X < 42"
    assert parse_expression(text) is parse_expression(text)


MALFORMED = [
    ("f(g(1)", "ends too early"),
    ("f(1))", "unexpected ')'"),
    ("?(a)", "unexpected '('"),
    ("?X <", "ends too early"),
    ("", "empty"),
    ("   ", "empty"),
    ("3", "not a predicate"),
    ("?X", "not a predicate"),
    ("a b", "unexpected 'b'"),
    ("f(,)", "unexpected ','"),
    ("'open", "unexpected"),
    ("p(?X > 2)", "inside not()"),
    ("not()", "not() needs"),
    ("a,, b", "unexpected ','"),
    ("p(1) < < 2", "unexpected"),
]


@pytest.mark.parametrize("text, detail", MALFORMED)
def test_malformed_expressions_get_the_paper_message(text, detail):
    with pytest.raises(BeliefSyntaxError) as caught:
        parse_expression(text)
    message = str(caught.value)
    assert message.startswith(f"The format of the belief expression {text.strip()[:40]}")
    assert "is not correct" in message and detail in message
    assert caught.value.kind == "WRONG_FORMAT"


def test_error_says_column_and_what_was_expected():
    with pytest.raises(BeliefSyntaxError) as caught:
        parse_expression("charge(battery ?X)")
    assert caught.value.column == 16
    assert "expected" in str(caught.value) and "','" in str(caught.value)


def test_huge_expressions_are_refused_or_parsed_never_crash():
    unbalanced = "f(" * 50_000  # 100 KB
    with pytest.raises(BeliefSyntaxError):
        parse_expression(unbalanced)
    deep = "f(" * 20_000 + "x" + ")" * 20_000
    with pytest.raises(BeliefSyntaxError, match=f"nested more than {MAX_TERM_DEPTH} levels deep at column"):
        parse_expression(deep)
    deepest = "f(" * (MAX_TERM_DEPTH - 1) + "[x]" + ")" * (MAX_TERM_DEPTH - 1)
    assert parse_expression(deepest).literals[0].term.name == "f"
    long = ", ".join(f"p{i}(x, {i})" for i in range(8_000))  # about 100 KB
    with pytest.raises(BeliefSyntaxError, match=f"8000 literals is more than the limit of {MAX_LITERALS}"):
        parse_expression(long)
    assert len(parse_expression(", ".join(f"p{i}(x)" for i in range(MAX_LITERALS))).literals) == MAX_LITERALS
    with pytest.raises(BeliefSyntaxError, match="longer than"):
        parse_expression("p(" + "x" * 300_000 + ")")


def test_non_text_is_a_syntax_error():
    with pytest.raises(BeliefSyntaxError):
        parse_expression(42)


def test_parse_belief_needs_one_ground_predicate():
    assert parse_belief("charge(battery, 80)") == Struct("charge", ("battery", 80))
    for bad in ["charge(battery, ?X)", "a(1), b(2)", "?X > 1", "not(a(1))"]:
        with pytest.raises(BeliefSyntaxError):
            parse_belief(bad)


scalars = st.one_of(
    st.integers(-10**6, 10**6),
    st.floats(allow_nan=False, allow_infinity=False, width=32),
    st.from_regex(r"[a-z_][a-zA-Z0-9_]{0,6}", fullmatch=True).filter(lambda s: s != "not"),
    st.text(st.characters(codec="ascii", exclude_characters="\n\r"), max_size=8),
)
values = st.one_of(
    scalars,
    st.lists(scalars, max_size=4).map(tuple),
    st.lists(scalars, max_size=4).map(ListTerm),
)


@settings(max_examples=300, deadline=None)
@given(st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True), st.lists(values, min_size=1, max_size=4))
def test_fast_fact_reading_agrees_with_the_grammar(name, args):
    text = format_term(Struct(name, tuple(args)))
    fast = _read_flat(text)
    slow = read_expression(text, text.strip())[0].term  # the grammar's reading (parse_expression tries _read_flat)
    assert fast is None or (fast == slow and format_term(fast) == format_term(slow))
    assert parse_belief(text) == slow
