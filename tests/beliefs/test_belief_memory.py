"""The belief memory: unification, exclusivity, persistence, negation, comparisons, listeners."""

import pytest
from aeroexec.beliefs import (
    BeliefError,
    BeliefMemory,
    BeliefSyntaxError,
    Struct,
    UnknownPredicateError,
    term,
)


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def now(self):
        return self.t


@pytest.fixture
def memory():
    m = BeliefMemory(multivalued={"sees"})
    for belief in [
        "object(m1, marker)", "code(m1, 3)", "object(m2, marker)", "code(m2, 7)",
        "object(b1, box)", "color(b1, red)", "position(m1, (1.0, 2.0, 0.5))",
        "flight_state(self, hovering)", "charge(battery, 55)", "visible(m1)",
        "position(self, (0.0, 0.0, 1.5))",
    ]:
        m.add(belief)
    return m


def test_query_returns_first_unification_as_python_values(memory):
    assert memory.query("object(?X, marker), code(?X, 3)") == {"?X": "m1"}
    assert memory.query("position(m1, ?P)") == {"?P": (1.0, 2.0, 0.5)}
    assert memory.query("position(self, (?x, ?y, ?z))") == {"?x": 0.0, "?y": 0.0, "?z": 1.5}
    assert memory.query("code(m1, 3)") == {}
    assert memory.query("code(m1, 4)") is None
    assert memory.query("unknown_thing(?X)") is None


def test_query_all_consult_and_holds(memory):
    assert memory.query_all("object(?X, marker)") == [{"?X": "m1"}, {"?X": "m2"}] or \
        sorted(s["?X"] for s in memory.query_all("object(?X, marker)")) == ["m1", "m2"]
    assert memory.consult("charge(battery, ?X)") == (True, {"?X": 55})
    assert memory.consult("charge(battery, 99)") == (False, {})
    assert memory.holds("object(?X, marker), code(?X, 7)")
    assert not memory.holds("object(?X, box), code(?X, ?)")


def test_adding_is_idempotent_and_remove_counts(memory):
    before = len(memory)
    assert memory.add("code(m1, 3)") is False
    assert len(memory) == before
    assert memory.remove("object(?X, marker)") == 2
    assert memory.remove("object(?X, marker)") == 0
    assert memory.remove("visible(m1)") == 1
    assert not memory.holds("visible(?)")


def test_exclusivity_retracts_the_old_value(memory):
    memory.add("charge(battery, full)")
    memory.add("charge(battery, empty)")
    assert memory.query_all("charge(battery, ?X)") == [{"?X": "empty"}]
    memory.add("position(self, (1.0, 1.0, 1.0))")
    assert memory.query_all("position(self, ?P)") == [{"?P": (1.0, 1.0, 1.0)}]
    # the key is every argument but the last
    memory.add("distance(a, b, 3)")
    memory.add("distance(a, c, 4)")
    memory.add("distance(a, b, 5)")
    assert sorted((s["?Y"], s["?D"]) for s in memory.query_all("distance(a, ?Y, ?D)")) == [
        ("b", 5), ("c", 4)]


def test_multivalued_predicates_keep_every_value(memory):
    memory.add("sees(self, m1)")
    memory.add("sees(self, m2)")
    assert sorted(s["?X"] for s in memory.query_all("sees(self, ?X)")) == ["m1", "m2"]
    declared = BeliefMemory()
    declared.declare("carry", 2, multivalued=True)
    declared.add("carry(self, a)")
    declared.add("carry(self, b)")
    assert len(declared.query_all("carry(self, ?X)")) == 2


def test_persistence_with_a_fake_clock():
    clock = FakeClock()
    m = BeliefMemory(persistence={"visible": 1.0}, clock=clock)
    m.add("visible(m1)")
    m.add("object(m1, marker)")
    clock.t = 0.6
    m.add("visible(m1)")  # seen again: its lifetime renews
    clock.t = 1.5
    assert m.holds("visible(m1)")
    clock.t = 1.7
    assert not m.holds("visible(m1)")
    assert m.holds("object(m1, marker)")  # permanent by default
    assert len(m) == 1


def test_negation_as_failure(memory):
    assert memory.holds("not(visible(m2))")
    assert not memory.holds("not(visible(m1))")
    assert memory.query_all("object(?X, marker), not(visible(?X))") == [{"?X": "m2"}]
    assert memory.holds("not(visible(?Anything), object(?Anything, box))")


def test_comparisons_and_builtins(memory):
    assert memory.query("charge(battery, ?X), ?X < 60") == {"?X": 55}
    assert memory.query("charge(battery, ?X), ?X > 60") is None
    assert memory.holds("charge(battery, ?X), ?X >= 55, ?X <= 55, ?X = 55, ?X != 54")
    assert memory.holds("charge(battery, ?X), less_than(?X, 56), greater_than(?X, 54)")
    assert memory.holds("flight_state(self, ?x), belong(?x, [moving, hovering])")
    assert not memory.holds("flight_state(self, ?x), belong(?x, [landed, landing])")
    assert sorted(s["?C"] for s in memory.query_all("code(?M, ?C), ?C > 2")) == [3, 7]
    # a comparison written first still works: the order is the planner's, not the text's
    assert memory.query("?C > 5, code(?M, ?C)") == {"?C": 7, "?M": "m2"}
    # comparing text with a number is simply false
    assert not memory.holds("color(b1, ?C), ?C > 3")


def test_tuples_lists_and_nested_terms():
    m = BeliefMemory()
    m.add("path(self, [[2.5, 3.2, 1.5], [1.2, 3.3, 1.5]])")
    m.add(term("carry", "self", term("box", "red", (1, 2))))
    assert m.query("path(self, ?P)") == {"?P": [[2.5, 3.2, 1.5], [1.2, 3.3, 1.5]]}
    assert m.query("path(self, [?First, ?])") == {"?First": [2.5, 3.2, 1.5]}
    assert m.query("carry(self, box(?C, (?, ?Y)))") == {"?C": "red", "?Y": 2}
    assert m.query("carry(self, box(blue, ?))") is None


def test_bindings_given_before_solving(memory):
    assert memory.holds("position(m1, ?P)", {"?P": (1.0, 2.0, 0.5)})
    assert not memory.holds("position(m1, ?P)", {"?P": [9, 9, 9]})


def test_listeners_hear_every_change():
    clock = FakeClock()
    m = BeliefMemory(persistence={"visible": 1.0}, clock=clock)
    heard = []
    unsubscribe = m.subscribe(lambda change: heard.append((change.kind, str(change.belief), change.reason)))
    m.add("charge(battery, full)")
    m.add("charge(battery, empty)")
    m.add("visible(m1)")
    m.remove("charge(battery, ?)")
    clock.t = 2.0
    m.holds("visible(?)")
    unsubscribe()
    m.add("charge(battery, full)")
    assert heard == [
        ("added", "charge(battery, full)", "add"),
        ("removed", "charge(battery, full)", "replaced"),
        ("added", "charge(battery, empty)", "add"),
        ("added", "visible(m1)", "add"),
        ("removed", "charge(battery, empty)", "remove"),
        ("removed", "visible(m1)", "expired"),
    ]


def test_a_listener_of_some_predicates_hears_only_theirs():
    m = BeliefMemory()
    heard, every = [], []
    m.subscribe(lambda change: every.append(str(change.belief)))
    unsubscribe = m.subscribe(lambda change: heard.append((change.kind, str(change.belief))), names=["charge"])
    m.add("speed(self, 3)")
    m.add("charge(battery, full)")
    m.add("charge(battery, low)")
    unsubscribe()
    m.add("charge(battery, empty)")
    assert heard == [("added", "charge(battery, full)"), ("removed", "charge(battery, full)"),
                     ("added", "charge(battery, low)")]
    assert len(every) == 6  # the listener of every change still hears it


def test_a_failing_listener_does_not_break_the_memory(caplog):
    m = BeliefMemory()
    m.subscribe(lambda change: 1 / 0)
    assert m.add("a(1)")
    assert m.holds("a(1)")
    assert "listener" in caplog.text


def test_computed_predicates():
    m = BeliefMemory()
    m.add("position(self, (0.0, 0.0, 1.0))")
    m.register("distance", 3, lambda a, b: sum((x - y) ** 2 for x, y in zip(a, b, strict=False)) ** 0.5)
    m.register("approximate_travel_time", 3, lambda a, b: sum(abs(x - y) for x, y in zip(a, b, strict=False)) / 2.0)
    assert m.query("position(self, ?P), distance(?P, (3.0, 4.0, 1.0), ?D)")["?D"] == 5.0
    assert m.holds("position(self, ?P), approximate_travel_time(?P, ?Y, ?T), ?T < 30",
                   {"?Y": (10.0, 0.0, 1.0)})
    assert not m.holds("position(self, ?P), approximate_travel_time(?P, ?Y, ?T), ?T < 3",
                       {"?Y": (10.0, 0.0, 1.0)})
    m.register("broken", 2, lambda a: 1 / 0)
    assert not m.holds("broken(1, ?X)")
    with pytest.raises(BeliefError):
        m.add("distance(a, b, 3)")


def test_declared_vocabulary_reports_unknown_predicates():
    m = BeliefMemory(predicates={"charge": 2, "visible": 1})
    m.add("charge(battery, 50)")
    with pytest.raises(UnknownPredicateError) as caught:
        m.query("chrge(battery, ?X)")
    assert str(caught.value) == (
        "The predicate chrge of the belief expression chrge(battery, ?X) does not exist")
    with pytest.raises(UnknownPredicateError, match="charge takes 2 arguments"):
        m.holds("charge(?X)")
    with pytest.raises(UnknownPredicateError):
        m.add("altitude(self, 3)")
    assert m.holds("charge(battery, ?X), ?X > 10, belong(?X, [50, 60])")


def test_bad_input_gives_the_syntax_error(memory):
    for bad in ["charge(battery", "?X", ""]:
        with pytest.raises(BeliefSyntaxError):
            memory.query(bad)
    with pytest.raises(BeliefSyntaxError):
        memory.add("charge(battery, ?X)")
    with pytest.raises(BeliefSyntaxError):
        memory.add(42)


def test_iteration_and_containment(memory):
    assert Struct("code", ("m1", 3)) in memory
    assert "code(m2, 7)" in memory
    assert [str(b) for b in memory.beliefs("code")] == ["code(m1, 3)", "code(m2, 7)"]
    memory.clear()
    assert len(memory) == 0


def test_answers_stay_right_as_the_memory_changes():
    m = BeliefMemory()
    query = "object(?X, marker), code(?X, ?C), ?C > 10"
    assert m.query_all(query) == []
    for k in range(200):
        m.add(f"object(o{k}, {'marker' if k % 2 else 'box'})")
        m.add(f"code(o{k}, {k})")
        expected = sorted(j for j in range(k + 1) if j % 2 and j > 10)
        assert sorted(s["?C"] for s in m.query_all(query)) == expected
    for k in range(0, 200, 3):
        m.remove(f"code(o{k}, ?)")
    expected = sorted(j for j in range(200) if j % 2 and j > 10 and j % 3)
    assert sorted(s["?C"] for s in m.query_all(query)) == expected


def test_check_verifies_an_expression_without_solving():
    m = BeliefMemory(predicates={"charge": 2})
    assert m.check("charge(battery, ?X), ?X < 10").predicates == {("charge", 2)}
    with pytest.raises(UnknownPredicateError):
        m.check("battery(?X)")
    with pytest.raises(BeliefSyntaxError):
        m.check("charge(battery")


def test_a_question_asked_again_is_answered_anew_as_soon_as_a_belief_it_reads_changes():
    # the memory answers a repeated question from its last answer while the relations it reads stand: every kind
    # of change must show at once (a tree ticks the same conditions 20 times a second)
    clock = FakeClock()
    m = BeliefMemory(persistence={"visible": 1.0}, clock=clock)
    m.add("charge(battery, 80)")
    question = "charge(battery, ?C), ?C > 20"
    assert m.query(question) == {"?C": 80}
    m.add("charge(battery, 15)")  # an exclusive value replaced
    assert m.query(question) is None and not m.holds(question)
    m.add("charge(battery, 30)")
    assert m.query(question) == {"?C": 30}
    m.query(question)["?C"] = 0  # an answer handed out is the caller's to change
    assert m.query(question) == {"?C": 30}
    assert m.holds("not(visible(?))")
    m.add("visible(marker_3)")
    assert not m.holds("not(visible(?))") and m.query("visible(?M)") == {"?M": "marker_3"}
    clock.t += 2.0  # its persistence ran out
    assert m.holds("not(visible(?))") and m.query("visible(?M)") is None
    m.add("visible(marker_3)")
    m.remove("visible(?)")
    assert m.query("visible(?M)") is None


def test_a_question_reading_a_computed_predicate_is_asked_every_time():
    m = BeliefMemory()
    calls = []
    level = [10]
    m.register("level", 1, lambda: calls.append(1) or level[0], inputs=0)
    assert m.query("level(?L)") == {"?L": 10}
    level[0] = 12
    assert m.query("level(?L)") == {"?L": 12} and len(calls) == 2


def test_holds_standing_gives_the_version_an_answer_stands_at_and_the_version_moves_with_every_change():
    """A behavior tree's condition answers from its last answer while the memory's ``version`` is the one
    ``holds_standing`` gave: every change that can change an answer moves it."""
    m = BeliefMemory(predicates={"charge": 2, "visible": 1})
    m.add("charge(battery, 55)")
    question = "charge(battery, ?C), ?C > 20"
    assert m.holds_standing("charge(battery, 55)") == (True, -1)  # a flat goal asked the first time: not kept yet
    assert m.holds_standing("charge(battery, 55)") == (True, m.version)
    assert m.holds_standing(question) == (True, m.version)
    for change in (lambda: m.add("charge(battery, 10)"), lambda: m.remove("charge(battery, ?)"),
                   lambda: m.declare("light", 2), lambda: m.add_rules("low :- charge(battery, ?C), ?C < 20."),
                   lambda: m.register("distance", 2, lambda x: 1.0), lambda: m.limit_rules(100)):
        before = m.version
        change()
        assert m.version != before
    assert m.holds_standing(question)[0] is False  # the charge was removed
    assert m.holds_standing("low") == (False, m.version)  # rules over stored beliefs: it stands
    m.add("charge(battery, 10)")
    assert m.holds_standing("low") == (True, m.version)


def test_holds_standing_never_stands_for_beliefs_that_expire_or_computed_answers():
    """A belief with a lifetime goes when its time is up, a computed predicate answers anew: neither moves the
    version, so a question reading them (through rules too) is asked every time."""
    clock = FakeClock()
    m = BeliefMemory(persistence={"visible": 1.0}, clock=clock)
    m.add("visible(m1)")
    m.add_rules("seen(?X) :- visible(?X).")
    level = [3]
    m.register("level", 1, lambda: level[0])
    for question in ("visible(m1)", "seen(m1)", "level(?L), ?L > 2"):
        m.holds_standing(question)
        assert m.holds_standing(question) == (True, -1), question
    clock.t = 1.5
    level[0] = 1
    assert [m.holds_standing(q)[0] for q in ("visible(m1)", "seen(m1)", "level(?L), ?L > 2")] == [False] * 3


def test_a_belief_added_again_with_the_value_it_has_changes_nothing_and_tells_no_listener():
    memory = BeliefMemory()
    memory.add("position(self, (1.0, 2.0, 3.0))")
    heard = []
    memory.subscribe(heard.append)
    version, changes = memory.version, memory.changes
    assert not memory.add(Struct("position", ("self", (1.0, 2.0, 3.0))))
    assert not memory.add("position(self, (1.0, 2.0, 3.0))")
    assert heard == [] and (memory.version, memory.changes) == (version, changes)
    assert memory.add(Struct("position", ("self", (1.0, 2.0, 3.5))))  # another value replaces it: both are told
    assert [(c.kind, c.reason, str(c.belief)) for c in heard] == [
        ("removed", "replaced", "position(self, (1.0, 2.0, 3.0))"), ("added", "add", "position(self, (1.0, 2.0, 3.5))")]
