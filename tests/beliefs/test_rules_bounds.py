"""Rules in flight are bounded: what would blow up is refused before flight with its file:line, the work of one
engine step is bounded in flight (a condition past it fails with the reason, the run does not crash), a join's
size is estimated before it is built, and a long chain of rules is loaded in little memory."""

from __future__ import annotations

import json
import tracemalloc

import pytest
from aeroexec.beliefs import BeliefMemory, EvaluationRefused, Struct, parse_rules
from aeroexec.cli.main import main
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.catalog.behavior_catalog import default_catalog_path, parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status

from aeroexec.limits import RULES_WORK_PER_STEP


def catalog_with(rules: str, **replaced: str):
    """The aerial catalog with ``rules:`` at its end and some of its text replaced (and the rules' first line)."""
    text = default_catalog_path().read_text()
    for old, new in replaced.items():
        assert old in text
        text = text.replace(old, new)
    text += "rules: |\n" + "".join(f"  {line}\n" for line in rules.splitlines())
    return parse_catalog(text, "aerial_rules.yaml"), text.count("\n") - len(rules.splitlines()) + 1


def N(kind: str, *children: TreeNode, **ports: str) -> TreeNode:  # noqa: N802
    return TreeNode(kind, "", dict(ports), list(children), "mission.xml", 0)

REACH = "reach(?A, ?B) :- object(?A, ?B).\nreach(?A, ?C) :- object(?A, ?B), reach(?B, ?C).\n"

CHECK = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <TAKE_OFF ALTITUDE="3"/>
      <CheckBelief belief="{belief}"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""

LOOP = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="i := 0; j := 1"/>
      <TAKE_OFF ALTITUDE="3"/>
      <Repeat num_cycles="400">
        <Sequence>
          <AddBelief belief="object(n{i}, n{j})"/>
          <Script code="i := i + 1; j := j + 1"/>
        </Sequence>
      </Repeat>
      <CheckBelief belief="reach(n0, n400)"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def chain(n: int) -> str:
    return "".join(f"object(n{i}, n{i + 1}).\n" for i in range(n))


def zones(n: int) -> str:
    return "".join(f"zone(z{i}).\n" for i in range(n))


@pytest.mark.parametrize(("rules", "belief", "line", "rule"), [
    (chain(3000) + REACH, "reach(n0, n3000)", 3001, "reach(?A, ?B) :- object(?A, ?B)."),
    (zones(170) + "trio(?A, ?B, ?C) :- zone(?A), zone(?B), zone(?C).\n", "trio(z1, z2, ?C)", 171, "trio(?A, ?B, ?C)"),
    (zones(3) + f"wide :- {', '.join(f'zone(?X{i})' for i in range(20))}.\n", "wide", 4, "wide :- zone(?X0)"),
], ids=["closure of 3,000 facts", "3-way product of 170 facts", "20 goals sharing no variable"])
def test_rules_that_would_stall_the_engine_are_refused_before_flight_with_their_line(tmp_path, capsys, rules, belief,
                                                                                      line, rule):
    path = tmp_path / "big.rules"
    path.write_text(rules)
    mission = tmp_path / "m.xml"
    mission.write_text(CHECK.format(belief=belief))
    assert main(["verify", str(mission), "--rules", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:{line}: evaluating the rule {rule}" in out
    assert "units of work in one ask (the limit of rules in flight, so that the engine loop never stalls): refused " \
           "before flight, with the facts given" in out and "Traceback" not in out
    assert main(["run", str(mission), "--rules", str(path), "--quiet", "--output", str(tmp_path / "out")]) == 1


def test_rules_past_the_bound_in_flight_fail_the_condition_with_the_reason_not_the_run(tmp_path, capsys):
    rules = tmp_path / "reach.rules"
    rules.write_text(REACH)
    mission = tmp_path / "loop.xml"
    mission.write_text(LOOP)  # 400 links added in flight: their closure (80,200 pairs) is more than a step may do
    assert main(["verify", str(mission), "--rules", str(rules)]) == 0
    code = main(["run", str(mission), "--rules", str(rules), "--plain", "--output", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 1 and "run_ended: failed" in out and "please report" not in out and "Traceback" not in out
    events = [json.loads(line) for line in (tmp_path / "out" / "events.jsonl").read_text().splitlines()]
    errors = [e["detail"] for e in events if e["kind"] == "tree_error"]
    assert errors == [f"{mission}:12: CheckBelief reach(n0, n400): {rules}:2: evaluating the rule reach(?A, ?C) :- "
                      f"object(?A, ?B), reach(?B, ?C). takes more than {RULES_WORK_PER_STEP:,} units of work in one "
                      "engine step (the limit of rules in flight, so that the engine loop never stalls): refused"]
    assert [e["kind"] for e in events if e["kind"].startswith("drone_")][-2:] == ["drone_landed", "drone_disarmed"]


def test_every_ask_of_one_engine_step_together_stays_within_the_bound():
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world,
                    rules=parse_rules(REACH + "pair(?A, ?B) :- object(?A, ?), object(?B, ?).", "reach.rules"))
    memory = engine.memory
    refused: list[str] = []
    spent: list[int] = []

    def ask() -> None:  # a tree asking three derived predicates in one step, each past the bound
        for question in ("reach(n0, n400)", "pair(n1, ?B)", "reach(n5, n9)"):
            try:
                memory.holds(question)
            except EvaluationRefused as error:
                refused.append(error.message)
            spent.append(memory._rule_budget.spent)

    try:
        for i in range(400):
            memory.add(Struct("object", (f"n{i}", f"n{i + 1}")))
        engine.tick_callbacks.append(ask)
        engine.tick()
        assert len(refused) == 3 and all("units of work in one engine step" in r for r in refused)
        assert max(spent) <= 2 * RULES_WORK_PER_STEP  # all three together, in one step
        assert spent[2] == spent[1]  # reach refused for the same beliefs: asked again at no cost
        assert len(memory._rulebook.derived[("reach", 2)].rows) <= 2 * RULES_WORK_PER_STEP
        refused.clear()
        engine.tick()  # the next step may spend again, and is refused again: nothing is built up past the bound
        assert len(refused) == 3
        memory.remove("object(?A, ?B)")
        for i in range(20):
            memory.add(Struct("object", (f"n{i}", f"n{i + 1}")))
        assert memory.holds("reach(n0, n20)") and memory.holds("pair(n1, n19)")  # small again: answered
    finally:
        engine.stop()


def test_a_join_is_refused_from_its_estimated_size_before_its_answers_are_built():
    memory = BeliefMemory(multivalued={"zone"})
    for i in range(140):
        memory.add(Struct("zone", (f"z{i}",)))
    memory.add_rules("trio(?A, ?B, ?C) :- zone(?A), zone(?B), zone(?C).", "zones.rules")
    tracemalloc.start()
    try:
        with pytest.raises(EvaluationRefused) as caught:
            memory.holds("trio(?A, ?B, ?C)")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert str(caught.value).startswith("zones.rules:1: the rule trio(?A, ?B, ?C) :- zone(?A), zone(?B), zone(?C). "
                                        "would build about 2,744,000 partial answers")
    assert "more than the limit of 256 MiB (goals that share no variable?): refused before building them" in str(
        caught.value)
    assert peak < 32 * 2 ** 20  # the 19,600 pairs before it, not the 2.7 million triples


def test_a_long_chain_of_rules_is_loaded_in_little_memory():
    text = "q0(?X) :- object(?X, ?).\n" + "".join(f"q{i + 1}(?X) :- q{i}(?X).\n" for i in range(3000))
    rules = parse_rules(text, "chain.rules")
    memory = BeliefMemory(predicates={"object": 2})
    tracemalloc.start()
    try:
        memory.add_rules(rules)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40 * 2 ** 20  # linear in the rules (the strata each stratum needs were kept per stratum: 220 MiB)
    memory.add("object(a, b)")
    assert memory.query_all("q3000(?X)") == [{"?X": "a"}]


def test_a_precondition_over_rules_past_the_bound_fails_the_behavior_with_the_reason():
    catalog, first = catalog_with("steady :- object(?A, ?), object(?B, ?), object(?C, ?).", **{
        "preconditions: flight_state(self, ?x), belong(?x, [moving, hovering]), not(stability(ground, unstable))":
        "preconditions: flight_state(self, ?x), belong(?x, [moving, hovering]), steady"})
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, catalog=catalog)
    try:
        for i in range(60):  # 216,000 triples: past the work of a step
            engine.memory.add(Struct("object", (f"n{i}", "marker")))
        mission = TreeMission(TreeDocument({"Main": N("Sequence", N("TAKE_OFF", ALTITUDE="2"), N("LAND"))}, "Main",
                                           "mission.xml"), engine)
        assert mission.run(60.0) == Status.FAILURE
        failed = engine.log.events(kind="failed_preconditions", behavior="LAND")[0].detail
        assert (f"aerial_rules.yaml:{first}: evaluating the rule steady :- object(?A, ?), object(?B, ?), "
                "object(?C, ?). takes more than 30,000 units of work in one engine step") in failed
        assert "raised" not in failed  # the reason, not an exception's name (and no traceback logged)
    finally:
        engine.stop()


def test_a_derived_predicate_grown_step_by_step_is_bounded_in_memory(monkeypatch):
    monkeypatch.setattr("aeroexec.beliefs.rules.derivation.MAX_DERIVED", 1_000)
    memory = BeliefMemory(multivalued={"object"})
    memory.limit_rules(RULES_WORK_PER_STEP, per_step=True)
    memory.add_rules(REACH, "reach.rules")
    with pytest.raises(EvaluationRefused) as caught:
        for i in range(100):  # a link a step: each step's new pairs are few, all of them together are not
            memory.renew_rules()
            memory.add(Struct("object", (f"n{i}", f"n{i + 1}")))
            memory.holds("reach(n0, ?X)")
    assert i < 50  # the link whose pairs passed the bound (45 links: 1,035 pairs)
    assert str(caught.value) == ("reach.rules:1: the rules of reach derive more than 1,000 beliefs (the limit of one "
                                 "derived predicate, for memory): refused")
    assert len(memory._rulebook.derived[("reach", 2)].rows) <= 1_000


def test_rules_refused_for_want_of_what_a_step_had_left_are_evaluated_again_next_step():
    memory = BeliefMemory(multivalued={"object", "zone"})
    memory.limit_rules(RULES_WORK_PER_STEP, per_step=True)
    memory.add_rules(REACH + "trio(?A, ?B, ?C) :- zone(?A), zone(?B), zone(?C).", "zones.rules")
    for i in range(100):
        memory.add(Struct("object", (f"n{i}", f"n{i + 1}")))
        memory.add(Struct("zone", (f"z{i}",)))
    memory.renew_rules()
    with pytest.raises(EvaluationRefused, match="zones.rules:3: "):
        memory.holds("trio(?A, ?B, ?C)")  # a million triples: it takes the step's work, and more
    with pytest.raises(EvaluationRefused, match="zones.rules:"):
        memory.holds("reach(n0, n100)")  # 5,050 pairs, but nothing left in this step
    memory.renew_rules()
    assert memory.holds("reach(n0, n100)")  # the next step: asked again, and answered
    with pytest.raises(EvaluationRefused, match="zones.rules:3: "):
        memory.holds("trio(?A, ?B, ?C)")


def test_before_flight_each_derived_predicate_is_tried_as_if_asked_first_and_alone():
    from aeroexec.engine.catalog import default_catalog
    from aeroexec.engine.catalog.vocabulary import check_rules
    own = {n: p for n, p in default_catalog().predicates.items() if not p.derived}
    independent = "".join(f"r{i}(?X) :- object(?X, m{i}).\n" for i in range(1000))  # all together: past the bound
    assert check_rules(own, parse_rules(independent, "many.rules")) == []
    chained = "q0(?X) :- object(?X, ?).\n" + "".join(f"q{i + 1}(?X) :- q{i}(?X).\n" for i in range(1000))
    problems = [str(p) for p in check_rules(own, parse_rules(chained, "chain.rules"))]
    assert problems == ["chain.rules:366: asking q365 evaluates its rules and those it reads in 30,012 units of work, "
                        "more than 30,000 in one ask (the limit of rules in flight, so that the engine loop never "
                        "stalls): refused before flight, with the facts given"]
