"""Derived beliefs everywhere a belief is asked: the catalog's rules (preconditions, reactive rules, lines of
errors), a rules file given to the engine and to verify, and tree conditions."""

from __future__ import annotations

from pathlib import Path

import pytest
from aeroexec.beliefs import RuleError, parse_rules
from aeroexec.cli.main import main
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.catalog.behavior_catalog import default_catalog_path, parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.errors import CatalogError
from aeroexec.trees.model import TreeDocument, TreeNode
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status

ROOT = Path(__file__).resolve().parents[2]


def catalog_with(rules: str, **replaced: str):
    """The aerial catalog with ``rules:`` at its end and some of its text replaced."""
    text = default_catalog_path().read_text()
    for old, new in replaced.items():
        assert old in text
        text = text.replace(old, new)
    text += "rules: |\n" + "".join(f"  {line}\n" for line in rules.splitlines())
    return parse_catalog(text, "aerial_rules.yaml"), text.count("\n") - len(rules.splitlines()) + 1


def N(kind: str, *children: TreeNode, **ports: str) -> TreeNode:  # noqa: N802
    return TreeNode(kind, "", dict(ports), list(children), "mission.xml", 0)


def test_catalog_rules_derive_what_preconditions_trees_and_reactive_rules_ask():
    rules = ("airborne :- flight_state(self, ?S), belong(?S, [moving, hovering]).\n"
             "ordered_down :- order(self, land).\n"
             "order(self, none).")
    catalog, first = catalog_with(
        rules, **{"  condition: charge(battery, ?X), less_than(?X, 10)": "  condition: ordered_down",
                  "- {predicate: result, arity: 2,": "- {predicate: order, arity: 2}\n- {predicate: result, arity: 2,"})
    assert [r.line for r in catalog.rules] == [first, first + 1, first + 2]
    assert catalog.predicates["airborne"].derived and catalog.predicates["ordered_down"].derived
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, catalog=catalog)
    try:
        assert not engine.memory.holds("airborne")
        tree = TreeDocument({"Main": N("Sequence", N("TAKE_OFF", ALTITUDE="2"), N("CheckBelief", belief="airborne"),
                                       N("WAIT", DURATION="30"))}, "Main", "mission.xml")
        mission = TreeMission(tree, engine)
        engine.timers.after(8.0, lambda: engine.memory.add("order(self, land)"))
        mission.run(60.0)
        landings = engine.log.events(kind="reactive", behavior="LAND")
        assert landings and landings[0].time >= 8.0, "the reactive rule over a derived predicate never fired"
        assert engine.log.events(kind="GOAL_ACHIEVED", behavior="LAND")
    finally:
        engine.stop()


def test_a_failed_precondition_over_a_derived_predicate_says_which_rule_failed():
    catalog, first = catalog_with("steady :- stability(ground, stable).", **{
        "preconditions: flight_state(self, ?x), belong(?x, [moving, hovering]), not(stability(ground, unstable))":
        "preconditions: flight_state(self, ?x), belong(?x, [moving, hovering]), steady"})
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, catalog=catalog)
    try:
        mission = TreeMission(TreeDocument({"Main": N("Sequence", N("TAKE_OFF", ALTITUDE="2"), N("LAND"))}, "Main",
                                           "mission.xml"), engine)
        assert mission.run(60.0) == Status.FAILURE
        failed = engine.log.events(kind="failed_preconditions", behavior="LAND")[0].detail
        assert f"the rule at aerial_rules.yaml:{first}" in failed
        assert "stability(ground, stable) does not hold" in failed
    finally:
        engine.stop()


@pytest.mark.parametrize(("rules", "message"), [
    ("position(?X) :- object(?X, ?).", "{line}: error: the rule position(?X) :- object(?X, ?). derives "
                                       "position/1, which clashes with the stored predicate position/2"),
    ("near(?X) :- distance_to(?X, ?D), ?D < 3.", "{line}: error: The rule near(?X) :- distance_to(?X, ?D), ?D < 3. "
                                                "is not safe: ?X appears only in the head and distance_to"),
    ("a :- object(?X, ?), not(b).\nb :- a.", "{line}: error: the negation in a :- object(?X, ?), not(b). cannot be "
                                             "stratified: a depends on its own negation (a -> not b -> a)"),
])
def test_catalog_rules_errors_name_the_catalog_line(rules, message):
    with pytest.raises(CatalogError) as caught:
        catalog_with(rules)
    first = default_catalog_path().read_text().count("\n") + 2
    assert message.format(line=f"aerial_rules.yaml:{first}") in str(caught.value)


def test_a_rules_file_given_to_the_engine_and_to_verify(tmp_path, capsys):
    rules = tmp_path / "zones.rules"
    rules.write_text("% markers worth landing on\npad(?M) :- object(?M, marker), code(?M, 3).\n")
    mission = tmp_path / "m.py"
    mission.write_text("import aeroexec.engine.api as api\n\n\ndef mission():\n"
                       "    if api.true_belief('pad(?M)'):\n        api.execute_behavior('TAKE_OFF')\n")
    assert main(["verify", str(mission)]) == 1  # pad is unknown without the rules
    assert "The predicate pad of the belief expression pad(?M) does not exist" in capsys.readouterr().out
    assert main(["verify", str(mission), "--rules", str(rules)]) == 0
    rules.write_text("% markers worth landing on\npad(?M) :- object(?M, marker), code(?M, ?C), ?C < ?Z.\n")
    assert main(["verify", str(mission), "--rules", str(rules)]) == 1
    assert f"{rules}:2: The rule pad(?M)" in capsys.readouterr().out
    world = default_world()
    engine = Engine(SimulatedDrone(world), obstacles=world, rules=parse_rules("pad(?M) :- code(?M, 3)."))
    try:
        engine.memory.add("code(marker_3, 3)")
        assert engine.memory.query("pad(?M)") == {"?M": "marker_3"}
    finally:
        engine.stop()
    with pytest.raises(RuleError, match="zones:1: The predicate nowhere of the rule"):
        Engine(SimulatedDrone(world), rules=parse_rules("pad(?M) :- nowhere(?M).", "zones"))


TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <AddRule rule="pad(pad_c, (2, -8)). pad(pad_a, (4, 2)). blocked(pad_a).
                     landing_pad(?P, ?X, ?Y) :- pad(?P, (?X, ?Y)), not(blocked(?P))."/>
      <TAKE_OFF ALTITUDE="3"/>
      <QueryBelief belief="landing_pad(?P, ?X, ?Y)"/>
      <GO_TO_POINT COORDINATES="{X}, {Y}, 3"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_a_tree_adds_rules_with_an_add_rule_node(tmp_path, capsys):
    mission = tmp_path / "pads.xml"
    mission.write_text(TREE)
    assert main(["run", str(mission), "--plain", "--output", str(tmp_path / "out")]) == 0
    assert "activated GO_TO_POINT: SPLINE=no, COORDINATES=(2, -8, 3)" in capsys.readouterr().out
    mission.write_text(TREE.replace("not(blocked(?P))", "not(blocked(?Q))"))
    assert main(["verify", str(mission)]) == 1
    assert (f"{mission}:4: error: WRONG_FORMAT: AddRule: The rule landing_pad(?P, ?X, ?Y) :- pad(?P, (?X, ?Y)), "
            "not(blocked(?Q)). is not safe: ?Q appears only in a negation") in capsys.readouterr().out


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


def readme_rules() -> str:
    """The rules example of the "Rules: derived beliefs" section (docs/beliefs.md), as written there."""
    text = (ROOT / "docs" / "beliefs.md").read_text()
    section = text[text.index("## Rules: derived beliefs"):]
    return section[section.index("```prolog\n") + len("```prolog\n"):section.index("```\n", section.index("```prolog"))]


def test_the_readme_rules_example_is_verified_and_flown_as_written(tmp_path, capsys):
    rules = tmp_path / "zones.rules"
    rules.write_text(readme_rules())
    assert "zone(z1)." in rules.read_text() and "safe_zone(?Z) :- zone(?Z)" in rules.read_text()
    mission = tmp_path / "zones.xml"
    mission.write_text(CHECK.format(belief="safe_zone(z1), not(safe_zone(z2)), reachable(wp1, wp2)"))
    assert main(["verify", str(mission), "--rules", str(rules)]) == 0
    assert "ready to fly" in capsys.readouterr().out
    assert main(["run", str(mission), "--rules", str(rules), "--plain", "--output", str(tmp_path / "out")]) == 0
    assert "run_ended: completed" in capsys.readouterr().out
    rules.write_text("zone(z1).\nsafe_zone(?Z) :- zone(?Z).\nzone(z2, big).\n")
    assert main(["verify", str(mission), "--rules", str(rules)]) == 1
    assert capsys.readouterr().out.splitlines()[0] == (
        f"{rules}:3: The predicate zone/2 of the fact zone(z2, big). does not exist (zone takes 1 argument)")
    rules.write_text("object(a).\nsafe_zone(?Z) :- zone(?Z).\nzone(z1).\n")
    assert main(["verify", str(mission), "--rules", str(rules)]) == 1
    assert (f"{rules}:1: The predicate object/1 of the fact object(a). does not exist (object takes 2 arguments)"
            in capsys.readouterr().out)


def test_a_negated_predicate_without_arguments_is_asked_in_flight(tmp_path, capsys):
    rules = tmp_path / "d.rules"
    rules.write_text("d1 :- object(?C, zzz).\nd4 :- not(d1).\n")
    mission = tmp_path / "d.xml"
    mission.write_text(CHECK.format(belief="d4"))
    assert main(["verify", str(mission), "--rules", str(rules)]) == 0
    assert main(["run", str(mission), "--rules", str(rules), "--plain", "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "run_ended: completed" in out and "itemgetter" not in out
