"""The text path of the belief memory: the hand reader of the common goal shape agrees with the grammar on the fuzz
corpus, a question asked once answers as its compiled query does, an exclusive belief replaced in place leaves every
index true, and ``count`` / ``answers`` agree with ``query_all`` on stored and derived beliefs."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from aeroexec.beliefs import BeliefMemory, BeliefSyntaxError, Goal, Struct, UnknownPredicateError, parse_expression
from aeroexec.beliefs.grammar_reading import read_expression
from aeroexec.beliefs.parser import read_flat_fact, read_flat_goal, read_flat_parts
from aeroexec.beliefs.terms import Var, format_term
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).parents[1] / "fuzz"))
import fuzzing  # noqa: E402 (the fuzz suite's seeds and edits, beside it)

SEEDS = [path.read_bytes() for path in sorted((Path(__file__).parents[1] / "fuzz" / "seeds").glob("*.belief"))] + [
    b"code(o500, 500)", b"color(o500, ?C)", b"position(o1, (0.5, 2.0, -1.5e3))", b"p(?, ?_1, +.5, -7, x_y)",
    b"pos( self ,( 1 , 2.5 ) , ?X )"]
TRICKY = ["f(1.)", "f(1_0)", "f(+.5)", "f(\x0b1)", "f(\x1c1)", "p(a,)", "p((1,2),)", "p(())", "p((1,(2)))", "f(1e400)",
          "f(" + "9" * 65 + ")", "not(a)", "p(a) % c", "p(a), q(b)", "p(a)) ", "p(?X, ?)", "p(?1a)", "p(x y)",
          "p( a , ( 1 , 2 ) )", "p(\u00e9)", "p(1.5.2)", "p(-)", "p(?-)", "p(.)", "p(1e5)", "p(1E+5)", "p(a)(b)",
          "p((a)", "p(a))", " p ( a ) ", "p(\n1\t)", "p()", "p", "p(a, (b, c), (d))", "P_1(A)", "_(_)"]


def _same(mine: Struct, grammar: Struct) -> bool:
    """Equal terms, anonymous variables matched by place (each ``?`` is its own variable: no two the same)."""
    anonymous: list[Var] = []

    def shape(value):
        if type(value) is Var:
            if value.anonymous:
                anonymous.append(value)
                return ("?",)
            return ("var", str(value))
        if type(value) is tuple:
            return ("tuple", *map(shape, value))
        return (type(value).__name__, value)
    alike = mine.name == grammar.name and list(map(shape, mine.args)) == list(map(shape, grammar.args))
    return alike and len(set(anonymous)) == len(anonymous)


def _grammar_goal(text: str) -> Struct | None:
    """The grammar's reading (Lark's, never the hand reader's, which ``parse_expression`` tries first)."""
    stripped = text.strip()
    if not stripped:
        return None
    try:
        literals = read_expression(text, stripped)
    except BeliefSyntaxError:
        return None
    if len(literals) != 1 or type(literals[0]) is not Goal:
        return None
    return literals[0].term


def _agrees(text: str) -> None:
    mine = read_flat_goal(text)
    if mine is None:
        return  # read by the grammar
    grammar = _grammar_goal(text)
    assert grammar is not None, f"{text!r}: read by hand as {mine}, refused by the grammar"
    assert _same(mine, grammar), f"{text!r}: read by hand as {mine}, by the grammar as {grammar}"
    again = read_flat_goal(text)  # its pieces known now: read from the reader's table of pieces
    assert again is not None and _same(again, grammar), f"{text!r}: read again as {again}, by the grammar as {grammar}"
    assert all(a is not b for a, b in zip(_anonymous(mine), _anonymous(again), strict=True)), \
        f"{text!r}: a ? read again is the variable of the first reading"
    fact = read_flat_fact(text)
    assert fact is None or (fact == grammar and format_term(fact) == format_term(grammar))
    asked = read_flat_parts(text, stored=False)  # a question asked once: its atoms not interned, read alike
    assert asked is not None and _same(Struct(*asked), grammar), f"{text!r}: read unstored as {asked}"


def _anonymous(goal: Struct) -> list[Var]:
    flat = [v for a in goal.args for v in (a if type(a) is tuple else (a,))]
    return [v for v in flat if type(v) is Var and v.anonymous]


@pytest.mark.parametrize("text", TRICKY)
def test_hand_reader_agrees_with_the_grammar_on_tricky_texts(text):
    _agrees(text)


def test_hand_reader_reads_the_common_shapes():
    assert read_flat_goal("code(o500, 500)") == Struct("code", ("o500", 500))
    assert read_flat_goal("position(o1, (0.5, 2.0, -1.5))") == Struct("position", ("o1", (0.5, 2.0, -1.5)))
    assert read_flat_goal("color(o500, ?C)") == Struct("color", ("o500", Var("?C")))
    assert read_flat_fact("color(o500, ?C)") is None  # a fact holds no variable


#: pieces texts are made of, few enough that a text repeats those of the texts before it (the reader keeps the
#: values of the pieces it read): names, variables, numbers (``-7`` beside ``7``: a piece is kept under its own text);
#: and, rarer, what is none of those
PIECES = ["o1", "o500", "red", "class_3", "_", "P_1", "?C", "?", "?_1", "0", "500", "7", "-7", "+3", "3", "007", "0.5",
          "1.5", "-1.5", "+.5", ".5", "1e5", "1E+5", "-1.5e3", "-0.0", "0.0"]
NOT_PIECES = ["not", "?1a", "?-", "1.", "1e400", "1_0", "9" * 65, "1.5.2", "-", ".", "", "x y", "a)", "(b", "é",
              "\x0b1", "'a'", '"a"', "[a]", "a%", "inf", "nan"]
SPACE = st.sampled_from(["", "", "", " ", " ", "  ", "\t", "\n", " \r\n", "\f"])  # what the grammar ignores


@st.composite
def flat_texts(draw) -> str:
    """A goal's text of pieces from :data:`PIECES` (now and then one of :data:`NOT_PIECES`), some in tuples, spaced
    as the grammar allows."""
    def piece() -> str:
        pool = NOT_PIECES if draw(st.integers(0, 19)) == 0 else PIECES
        return draw(SPACE) + draw(st.sampled_from(pool)) + draw(SPACE)

    args = []
    for _ in range(draw(st.integers(1, 4))):
        if draw(st.booleans()):
            args.append(draw(SPACE) + "(" + ",".join(piece() for _ in range(draw(st.integers(1, 3)))) + ")"
                        + draw(SPACE))
        else:
            args.append(piece())
    name = draw(st.sampled_from(["code", "color", "position", "p", "P_1", "_", "code", "color", "not", "1p", ""]))
    return draw(SPACE) + name + draw(SPACE) + "(" + ",".join(args) + ")" + draw(SPACE)


@settings(max_examples=600, deadline=None)
@given(st.lists(flat_texts(), min_size=1, max_size=6))
def test_hand_reader_agrees_with_the_grammar_on_texts_of_pieces_read_before(texts):
    """Texts sharing their pieces: a piece read before is looked up, and still reads as the grammar reads it."""
    for text in texts:
        _agrees(text)


edits = st.lists(st.builds(fuzzing.Edit, st.sampled_from(fuzzing.KINDS), st.integers(0, 65535),
                           st.integers(0, 10_000), st.integers(0, len(fuzzing.PAYLOADS) - 1)), min_size=1, max_size=3)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SEEDS), edits)
def test_hand_reader_agrees_with_the_grammar_on_the_fuzz_corpus(seed, changes):
    _agrees(fuzzing.apply(seed, changes).decode("utf-8", "replace"))


def _memory(**kwargs) -> BeliefMemory:
    memory = BeliefMemory(multivalued={"seen"}, **kwargs)
    memory.add_all(["code(o1, 1)", "code(o2, 2)", "color(o1, red)", "position(o1, (1.0, 2.0, 3.0))",
                    "seen(o1, a)", "seen(o1, b)", "visible(o2)"])
    return memory


QUESTIONS = ["code(o1, 1)", "code(o1, 2)", "code(o9, 9)", "color(o1, ?C)", "color(o2, ?C)", "color(o1, ?)",
             "position(o1, ?P)", "position(o1, (1.0, 2.0, 3.0))", "seen(o1, ?X)", "visible(o2)", "visible(?X)",
             "nothing(a, ?X)", "code(?X, 2)", "linked(o1, ?Y)", "near(o1, ?Y)"]


def test_a_question_asked_once_answers_as_its_compiled_query():
    """The first ask of a text is answered by the quick path, the second compiles it, the third probes the compiled
    query: all three answer as the parsed expression does."""
    for question in QUESTIONS:
        memory = _memory()
        memory.add_rules("linked(?A, ?B) :- seen(?A, ?B).")
        memory.register("near", 2, lambda a: "o2")
        expected = memory.query(parse_expression(question))
        assert [memory.query(question) for _ in range(3)] == [expected] * 3, question
        memory = _memory()
        memory.add_rules("linked(?A, ?B) :- seen(?A, ?B).")
        memory.register("near", 2, lambda a: "o2")
        assert [memory.holds(question) for _ in range(3)] == [expected is not None] * 3, question


def test_a_question_asked_once_respects_the_vocabulary_and_its_spellings():
    memory = BeliefMemory(predicates={"code": 2})
    memory.declare("state", 2, values=["low", "high"])
    memory.add("code(o1, 1)")
    memory.add("state(battery, LOW)")
    assert memory.query("state(battery, low)") == {}
    assert memory.query("state(battery, ?S)") == {"?S": "low"}
    with pytest.raises(UnknownPredicateError):
        memory.query("colour(o1, ?C)")
    with pytest.raises(UnknownPredicateError):
        memory.query("code(o1, 1, 2)")
    with pytest.raises(UnknownPredicateError):
        memory.add("code(o1, 1, 2)")


def test_a_question_asked_once_follows_what_answers_its_predicate():
    """The relation a question asked once read straight is read so no longer once its predicate is respelled,
    computed, shared or derived: each new text answers as the parsed expression does."""
    memory = BeliefMemory()
    memory.add("state(battery, low)")
    assert memory.query("state(battery, low)") == {}
    memory.declare("state", 2, values=["low", "high"])
    assert memory.query("state(battery, LOW)") == {}
    memory = BeliefMemory()
    memory.add_all(["near(o1, o2)", "seen(o1, a)", "link(o1, b)"])
    assert memory.query("near(o1, ?Y)") == {"?Y": "o2"}
    memory.register("near", 2, lambda a: "o3")
    assert memory.query("near(o1,  ?Y)") == {"?Y": "o3"}
    assert memory.query("seen(o1, ?X)") == {"?X": "a"}
    memory.add_rules("seen(?A, ?B) :- link(?A, ?B).")
    for text in ["seen(o1,  b)", "seen(o1, ?X)"]:
        assert memory.query(text) == memory.query(parse_expression(text)), text
    assert memory.query("seen(o1,  b)") == {}


def test_a_question_asked_once_sees_expired_beliefs_gone():
    now = [0.0]
    memory = BeliefMemory(persistence={"seen_at": 1.0}, clock=lambda: now[0])
    memory.add("seen_at(o1, 5)")
    now[0] = 2.0
    assert memory.query("seen_at(o1, ?T)") is None
    assert memory.query("seen_at(o1, 5)") is None


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["pos", "pair"]), st.integers(0, 3), st.integers(0, 3),
                          st.integers(0, 4)), min_size=1, max_size=40))
def test_replacing_an_exclusive_belief_keeps_every_index_true(changes):
    """Each key holds its last value; every index and every way of asking agrees with that."""
    memory = BeliefMemory()
    held: dict[tuple, int] = {}
    for name, a, b, value in changes:
        key = (name, a) if name == "pos" else (name, a, b)
        held[key] = value
        memory.add(Struct(name, (*key[1:], value)))
    for key, value in held.items():
        name, args = key[0], key[1:]
        ask = ", ".join(map(str, args))
        assert memory.query(f"{name}({ask}, ?V)") == {"?V": value}
        assert {"?V": value} in memory.query_all(f"{name}({ask}, ?V)")
        assert memory.query_all(parse_expression(f"{name}(?A, ?B{', ?C' if name == 'pair' else ''})"))  # a scan
    for name in ("pos", "pair"):
        rows = {k[1:] + (v,) for k, v in held.items() if k[0] == name}
        pattern = "pos(?A, ?V)" if name == "pos" else "pair(?A, ?B, ?V)"
        assert set(memory.answers(pattern)) == rows
        for value in range(5):  # by the last place: the index of the values replaced
            asked = f"pos(?A, {value})" if name == "pos" else f"pair(?A, ?B, {value})"
            assert memory.count(asked) == sum(1 for r in rows if r[-1] == value)
        for first in range(4):  # by the first place: the index of the keys
            asked = f"pos({first}, ?V)" if name == "pos" else f"pair({first}, ?B, ?V)"
            assert memory.count(asked) == sum(1 for r in rows if r[0] == first)
    assert len(memory) == len(held)


CLOSURE = """reachable(?A, ?B) :- link(?A, ?B).
reachable(?A, ?C) :- link(?A, ?B), reachable(?B, ?C)."""


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6)), max_size=14),
       st.lists(st.tuples(st.booleans(), st.integers(0, 6), st.integers(0, 6)), max_size=8))
def test_count_and_answers_agree_with_query_all_through_updates(links, updates):
    memory = BeliefMemory(multivalued={"link"})
    for a, b in links:
        memory.add(Struct("link", (a, b)))
    memory.add_rules(CLOSURE)
    for add, a, b in [(True, 0, 0), *updates]:
        (memory.add if add else memory.remove)(Struct("link", (a, b)))
        for asked in ("reachable(?A, ?B)", "reachable(0, ?B)", "reachable(?A, ?A)", "reachable(?, ?B)",
                      "link(?A, ?B), reachable(?B, ?A)", "link(?A, ?B)"):
            every = memory.query_all(asked)
            assert memory.count(asked) == len(every), asked
            names = parse_expression(asked).variables
            assert sorted(memory.answers(asked)) == sorted(tuple(d[str(v)] for v in names) for d in every), asked


def test_answers_are_taken_when_asked():
    memory = BeliefMemory(multivalued={"link"})
    memory.add_all(["link(1, 2)", "link(2, 3)"])
    memory.add_rules(CLOSURE)
    found = memory.answers("reachable(?A, ?B)")
    memory.add("link(3, 4)")
    assert sorted(found) == [(1, 2), (1, 3), (2, 3)]
    assert memory.count("reachable(?A, ?B)") == 6
    assert memory.count("reachable(1, ?B)", {"?B": 4}) == 1



#: a thing's text in a belief, and the value an answer gives for it
THINGS = {"o1": "o1", "o2": "o2", "7": 7, "2.5": 2.5, "[1, 2]": [1, 2]}
SHAPES = ("object(?, a)", "visible(?)", "color(?, red)")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([*SHAPES, "object(?, b)"]), st.sampled_from(sorted(THINGS)),
                          st.booleans()), max_size=30))
@example([(shape, thing, True) for thing in ("[1, 2]", "7") for shape in SHAPES])  # a list's answer is a list
def test_goals_on_one_variable_answer_every_value_they_share_through_updates(changes):
    memory = BeliefMemory(multivalued={"object", "color"})
    held: set[tuple[str, str]] = set()
    asked = "object(?X, a), visible(?X), color(?X, red)"
    for shape, thing, add in changes:
        (memory.add if add else memory.remove)(shape.replace("?", thing))
        (held.add if add else held.discard)((shape, thing))
        every = memory.query_all(asked)
        shared = [value for thing, value in THINGS.items() if all((s, thing) in held for s in SHAPES)]
        assert sorted(every, key=repr) == sorted(({"?X": value} for value in shared), key=repr)  # types too
        assert memory.count(asked) == len(every)
        assert (memory.query(asked) is None) == (not every)
