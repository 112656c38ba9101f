"""Rules in the belief memory: the language, the errors with their lines, derivation kept up to date, proofs."""

from __future__ import annotations

from pathlib import Path

import pytest
from aeroexec.beliefs import BeliefError, BeliefMemory, RuleError, Struct, parse_rules
from aeroexec.beliefs.rules import joins

ZONES = """% where a drone may land
safe_zone(?Z) :- zone(?Z), not(occupied(?Z)), wind(?Z, ?W), ?W < 8.
reachable(?A, ?B) :- link(?A, ?B).
reachable(?A, ?C) :- link(?A, ?B), reachable(?B, ?C).
zone(z1). zone(z2). zone(z3).
occupied(z2).
link(a, b). link(b, c). link(c, a). link(c, d).
"""


@pytest.fixture
def memory() -> BeliefMemory:
    memory = BeliefMemory(multivalued={"wind"})
    memory.add_rules(ZONES, "zones.rules")
    for zone, wind in (("z1", 3), ("z2", 1), ("z3", 9)):
        memory.add(Struct("wind", (zone, wind)))
    return memory


def answers(memory: BeliefMemory, expression: str) -> list[tuple]:
    return sorted(tuple(a.values()) for a in memory.query_all(expression))


def test_rules_are_read_with_their_lines_and_facts_become_beliefs(memory):
    rules = parse_rules(ZONES, "zones.rules")
    assert [r.line for r in rules if r.body.literals] == [2, 3, 4]
    assert str(rules[0]) == "safe_zone(?Z) :- zone(?Z), not(occupied(?Z)), wind(?Z, ?W), ?W < 8."
    assert "zone(z3)" in memory and "link(c, a)" in memory  # facts of a rules file are sets: link(c, d) kept both
    assert len(memory.rules) == 3


def test_derived_beliefs_are_asked_like_stored_ones(memory):
    assert answers(memory, "safe_zone(?Z)") == [("z1",)]
    assert memory.holds("reachable(a, d), safe_zone(z1)")
    assert not memory.holds("reachable(d, ?X)")
    assert memory.query("reachable(b, ?X), ?X != b, ?X != c, ?X != d") == {"?X": "a"}
    assert len(answers(memory, "reachable(?A, ?B)")) == 12
    assert memory.beliefs("safe_zone") == [Struct("safe_zone", ("z1",))]  # what the fleet link shares
    assert memory.is_derived("reachable", 2) and not memory.is_derived("link", 2)


def test_answers_follow_the_facts_they_are_derived_from(memory):
    memory.add("wind(z3, 2)")
    assert answers(memory, "safe_zone(?Z)") == [("z1",), ("z3",)]
    memory.add("occupied(z1)")
    assert answers(memory, "safe_zone(?Z)") == [("z3",)]
    memory.remove("link(c, a)")
    assert not memory.holds("reachable(c, a)") and memory.holds("reachable(a, d)")
    memory.add("link(d, a)")
    assert len(answers(memory, "reachable(?A, ?B)")) == 16
    memory.clear()
    assert answers(memory, "reachable(?A, ?B)") == [] and not memory.holds("safe_zone(?Z)")


def test_asking_again_while_nothing_changed_costs_a_look_up(memory, monkeypatch):
    memory.add("position(self, (0, 0, 5))")
    assert memory.holds("safe_zone(z1)")
    calls = []
    real = joins.evaluate
    monkeypatch.setattr("aeroexec.beliefs.rules.derivation.evaluate", lambda *a: calls.append(a) or real(*a))
    for step in range(100):  # a condition ticked every period while the drone moves
        memory.add(Struct("position", ("self", (step, 0, 5))))
        assert memory.holds("safe_zone(z1)")
    assert calls == []  # no rule evaluated: the relations they read did not change
    memory.add("occupied(z1)")
    assert not memory.holds("safe_zone(z1)")
    assert calls  # now they were


def test_derived_beliefs_follow_expiry_and_computed_predicates():
    clock = [0.0]
    memory = BeliefMemory(persistence={"seen": 1.0}, clock=lambda: clock[0])
    memory.register("far", 1, lambda d: d > 10, inputs=1)
    memory.add_rules("target(?X) :- seen(?X, ?D), far(?D).\nclose(?X) :- seen(?X, ?D), not(far(?D)).")
    memory.add("seen(m1, 20)")
    memory.add("seen(m2, 5)")
    assert answers(memory, "target(?X)") == [("m1",)] and answers(memory, "close(?X)") == [("m2",)]
    clock[0] = 2.0
    assert answers(memory, "target(?X)") == []


def test_aliases_and_spellings_apply_inside_rules():
    memory = BeliefMemory(predicates={"flight_state": 2})
    memory.declare("flight_state", 2, values=("landed", "hovering", "moving"),
                   aliases={"flying": ("hovering", "moving")})
    memory.add_rules("airborne(?D) :- flight_state(?D, FLYING).")
    memory.add("flight_state(self, HOVERING)")
    assert answers(memory, "airborne(?D)") == [("self",)]


@pytest.mark.parametrize(("rules", "message"), [
    ("p(?X) :- q(?Y).", "rules.pl:1: The rule p(?X) :- q(?Y). is not safe: ?X appears only in the head"),
    ("p(?X) :- q(?X), not(r(?Y)).", "?Y appears only in a negation"),
    ("p(?X) :- q(?X), ?Y < 3.", "?Y appears only in a comparison"),
    ("p(?X) :- q(?X), not(p(?X)).", "cannot be stratified: p depends on its own negation (p -> not p)"),
    ("a(?X) :- q(?X), not(b(?X)).\nb(?X) :- q(?X), c(?X).\nc(?X) :- a(?X).",
     "rules.pl:1: the negation in a(?X) :- q(?X), not(b(?X)). cannot be stratified: a depends on its own "
     "negation (a -> not b -> c -> a)"),
    ("distance(?A, ?B, ?D) :- pair(?A, ?B), q(?D).", "derives distance, which is computed by the engine"),
    ("charge(?X, ?Y) :- pair(?X, ?Y).", "clashes with the stored predicate charge"),
    ("charge(?X) :- q(?X).", "derives charge/1, which clashes with the stored predicate charge/2"),
    ("p(?X) :- unknown_thing(?X).", "The predicate unknown_thing of the rule p(?X) :- unknown_thing(?X). does "
                                    "not exist"),
    ("n(?X) :- q(?X).\nn(?Y) :- n(?X), next(?X, ?Y).", "rules.pl:2: The recursive rule n(?Y) :- n(?X), "
                                                       "next(?X, ?Y). could derive beliefs without end"),
    ("n(?X) :- q(?X).\nn((?X, 1)) :- n(?X), q(?X).", "its head builds the new term (?X, 1)"),
    ("p(?X) :- q(?X)\nq(?X) :- r(?X).", "rules.pl:2:1: The format of the rule"),
    ("q(a).\ncode(m1, 1e400).", "rules.pl:2: The value 1e400 of code(m1, 1e400). is not correct (a finite number "
                                "is expected)"),
    ("p(?X) :- q(?X), pair(?X, ?V), ?V < -1e999.", "rules.pl:1: The value -1e999 of p(?X) :- q(?X), pair(?X, ?V), "
                                                   "?V < -1e999. is not correct (a finite number is expected)"),
])
def test_each_mistake_is_told_with_its_line(rules, message):
    memory = BeliefMemory(predicates={"q": 1, "r": 1, "charge": 2, "pair": 2})
    memory.register("distance", 3, lambda a, b: 1.0, inputs=2)
    memory.register("next", 2, lambda x: x + 1, inputs=1)
    with pytest.raises(RuleError) as caught:
        memory.add_rules(rules, "rules.pl")
    assert message in str(caught.value)
    assert all(p.line for p in caught.value.problems)
    assert memory.rules == ()  # nothing added


def test_why_gives_the_proof_and_why_not_the_goal_that_failed(memory):
    proof = memory.why("reachable(a, d)")[0]
    text = str(proof)
    assert text.splitlines()[0].startswith("reachable(a, d)  <- the rule at zones.rules:4")
    assert "link(c, d)  <- a belief" in text
    assert [str(p) for p in memory.why("safe_zone(?Z)")[0].premises] == [
        "zone(z1)  <- a belief", "not(occupied(z1))  <- no belief matches it", "wind(z1, 3)  <- a belief",
        "3 < 8  <- the comparison holds"]
    assert memory.why("safe_zone(z3)") is None
    reasons = memory.why_not("safe_zone(z3)")
    assert reasons[0] == "safe_zone(z3) does not hold"
    assert "zones.rules:2" in reasons[1] and "9 < 8 does not hold" in reasons[1]
    assert "occupied(z2) holds" in " ".join(memory.why_not("safe_zone(z2)"))
    assert "the memory holds no link(d, ?)" in " ".join(memory.why_not("reachable(d, a)"))
    assert memory.why_not("safe_zone(z1)") == []


def test_a_derived_predicate_may_also_hold_beliefs_told_by_others(memory):
    memory.add("safe_zone(z7)")  # e.g. shared by another drone of the fleet
    assert answers(memory, "safe_zone(?Z)") == [("z1",), ("z7",)]
    assert str(memory.why("safe_zone(z7)")[0]) == "safe_zone(z7)  <- a belief"
    memory.remove("safe_zone(z7)")
    assert answers(memory, "safe_zone(?Z)") == [("z1",)]


def test_a_number_beyond_a_float_is_a_wrong_value_as_a_belief_too():
    memory = BeliefMemory()
    with pytest.raises(BeliefError, match="the value 1e400 is not correct \\(a finite number is expected\\)"):
        memory.add("code(m1, 1e400)")
    memory.add("code(m1, 1e308)")
    assert memory.query_all("code(m1, ?V)") == [{"?V": 1e308}]


def test_rules_longer_than_the_limit_are_refused_with_the_readme_words(tmp_path):
    from aeroexec.beliefs import read_rules
    from aeroexec.beliefs.parser import MAX_RULES_LENGTH
    assert MAX_RULES_LENGTH == 2_000_000  # the limits table (docs/reference/limits.md) says so
    readme = (Path(__file__).resolve().parents[2] / "docs" / "reference" / "limits.md").read_text()
    assert "| 2,000,000 characters | `file: the rules are N characters, more than the limit of 2,000,000` |" in readme
    path = tmp_path / "big.rules"
    comment = "% " + "x" * 97 + "\n"  # 100 characters a line: a file of comments is read quickly
    text = comment * (MAX_RULES_LENGTH // len(comment) - 1) + "zone(z1).\n".ljust(100, " ")
    path.write_text(text)
    assert len(text) == MAX_RULES_LENGTH and [str(r) for r in read_rules(path)] == ["zone(z1)."]
    path.write_text(text + "z.")
    with pytest.raises(RuleError) as caught:
        read_rules(path)
    assert str(caught.value) == f"{path}: the rules are 2,000,002 characters, more than the limit of 2,000,000"
