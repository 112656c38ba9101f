"""Safety rules as the operator writes them: read from a rules file, a catalog, a tree's section and a Python
mission's declaration; every mistake refused with the file and line, in words."""

from __future__ import annotations

import textwrap

import pytest
from aeroexec.cli.main import main
from aeroexec.engine.catalog import default_catalog, parse_catalog
from aeroexec.engine.safety.declared import mission_rules, rules_file

MISSION = """<root BTCPP_format="4" main_tree_to_execute="M">
  <BehaviorTree ID="M">
    <Sequence>
      <TAKE_OFF ALTITUDE="6"/>
      <GO_TO_POINT COORDINATES="{point}"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def write(path, text):
    path.write_text(textwrap.dedent(text))
    return path


@pytest.mark.parametrize("rule, line, words", [
    ("- rule: broken\n  never: charge(battery, ?c), ?c <\n  contingency: land\n", 2, "never"),
    ("- rule: unknown\n  always: fuel(tank, ?f), ?f > 10\n  contingency: land\n", 2, "fuel"),
    ("- rule: odd\n  never: charge(battery, ?c), ?c < 20\n  contingency: pray\n", 3, "unknown contingency 'pray'"),
    ("- rule: formless\n  contingency: land\n", 1, "exactly one of always, never, within"),
    ("- rule: late\n  within: 30\n  after: communication(wireless, lost)\n  contingency: land\n", 1, "ensure"),
], ids=["syntax", "unknown predicate", "unknown contingency", "no form", "within without ensure"])
def test_a_wrong_rule_is_refused_with_its_file_and_line(tmp_path, capsys, rule, line, words):
    rules = write(tmp_path / "rules.yaml", "# the field's rules\n" + rule)
    mission = write(tmp_path / "m.xml", MISSION.format(point="2, 2, 6"))
    assert main(["verify", str(mission), "--safety-rules", str(rules)]) == 1
    out = capsys.readouterr().out
    assert f"{rules}:{line + 1}: error: " in out and words in out and "Traceback" not in out
    assert main(["run", str(mission), "--safety-rules", str(rules), "--quiet", "--output", str(tmp_path / "o")]) == 1


def test_rules_come_from_the_catalog_a_tree_and_a_python_mission(tmp_path):
    catalog = default_catalog()
    tree = write(tmp_path / "t.xml", MISSION.replace("  <BehaviorTree", """  <SafetyRules><![CDATA[
    - rule: tower
      never: position(self, ?p), distance(?p, (8, 8, 5), ?d), ?d < 5
      contingency: hold
      priority: 2
  ]]></SafetyRules>
  <BehaviorTree""", 1).format(point="2, 2, 6"))
    found = mission_rules(tree, catalog)
    assert not found.problems and [(r.name, r.line, r.priority, str(r.contingency)) for r in found.rules] == [
        ("tower", 3, 2, "hold")]
    python = write(tmp_path / "m.py", '''\
        from aeroexec.engine.api import execute_behavior

        SAFETY_RULES = """
        - rule: wind
          never: wind(self, ?w), ?w > 9
          contingency: call go_home
        - rule: clock
          never: mission_time(?t), ?t > 600
          contingency: return home
        """


        def go_home():
            execute_behavior("LAND")


        def mission():
            execute_behavior("TAKE_OFF", ALTITUDE=3)
        ''')
    found = mission_rules(python, catalog)
    assert not found.problems
    assert [(r.name, r.line, str(r.contingency)) for r in found.rules] == [("wind", 4, "call go_home"),
                                                                           ("clock", 7, "return home")]
    wrong = write(tmp_path / "w.py", python.read_text().replace("call go_home", "call go_hom"))
    (problem,) = mission_rules(wrong, catalog).problems
    assert problem.line == 6 and "go_hom" in problem.message and "go_home" in problem.message  # did you mean
    # a mission that never names SAFETY_RULES declares none (it is not parsed again for them); one whose name is
    # written in other letters Python reads as it (NFKC: fullwidth S) still declares its rules
    assert mission_rules(write(tmp_path / "n.py", "def mission():\n    pass\n"), catalog).rules == []
    wide = write(tmp_path / "u.py", python.read_text().replace("SAFETY_RULES =", "\uff33AFETY_RULES ="))
    assert [r.name for r in mission_rules(wide, catalog).rules] == ["wind", "clock"]
    from pathlib import Path

    text = Path(default_catalog().source).read_text()
    extra = text + "\nsafety_rules:\n- rule: low\n  never: charge(battery, ?c), ?c < 15\n  contingency: land\n"
    assert [r.name for r in parse_catalog(extra, "c.yaml").safety_rules] == ["low"]


def test_two_rules_of_one_name_are_refused(tmp_path):
    rules = write(tmp_path / "r.yaml", """\
        safety_rules:
        - {rule: a, never: "charge(battery, ?c), ?c < 15", contingency: land}
        - {rule: a, never: "charge(battery, ?c), ?c < 10", contingency: land}
        """)
    (problem,) = rules_file(rules, default_catalog()).problems
    assert problem.line == 3 and "defined twice" in problem.message


def test_a_literal_waypoint_in_a_keep_out_volume_is_refused_by_verify(tmp_path, capsys):
    rules = write(tmp_path / "rules.yaml", """\
        - rule: keep_out_tower
          never: position(self, ?p), distance(?p, (15, -15, 6), ?d), ?d < 5
          contingency: hold
        """)
    inside = write(tmp_path / "in.xml", MISSION.format(point="13, -13, 6"))
    assert main(["verify", str(inside), "--safety-rules", str(rules)]) == 1
    out = capsys.readouterr().out
    assert f"{inside}:5: error: the destination (13, -13, 6)" in out and "keep_out_tower" in out
    assert f"({rules}:1)" in out
    outside = write(tmp_path / "out.xml", MISSION.format(point="5, -5, 6"))
    assert main(["verify", str(outside), "--safety-rules", str(rules)]) == 0


def test_a_route_whose_battery_use_breaks_the_return_margin_is_refused(tmp_path, capsys):
    rules = write(tmp_path / "rules.yaml", """\
        - rule: margin
          always: return_margin(self, ?m), ?m >= 97
          contingency: return
        """)
    legs = "\n".join(f'      <GO_TO_POINT COORDINATES="{x}, {y}, 6"/>' for x, y in [(15, 0), (15, 15), (-15, 15)] * 2)
    mission = write(tmp_path / "long.xml", MISSION.replace('      <GO_TO_POINT COORDINATES="{point}"/>', legs))
    assert main(["verify", str(mission), "--safety-rules", str(rules)]) == 1
    out = capsys.readouterr().out
    assert "breaks safety rule margin" in out and "% left on arrival" in out


KEEP_OUT = """\
    - rule: keep_out_tower
      never: position(self, ?p), distance(?p, (15, -15, 6), ?d), ?d < 5
      contingency: hold
    """
PYTHON = """\
import aeroexec.engine.api as api


def runMission():
    api.executeBehavior("TAKE_OFF", altitude=6)
    {call}
    api.executeBehavior("LAND")
"""
AEROSTACK2 = """\
from as2_python_api.drone_interface import DroneInterface

uav = DroneInterface("drone0")
uav.takeoff(6.0, 1.0)
{call}
uav.land()
"""


@pytest.mark.parametrize("source, call", [
    (PYTHON, 'api.executeBehavior("GO_TO_POINT", coordinates=[13, -13, 6])'),  # the README's spelling
    (PYTHON, 'api.executeBehavior("GO_TO_POINT", point=[13, -13, 6])'),  # figure10.py's
    (PYTHON, 'api.executeBehavior("go_to_point", Coordinates=(13, -13, 6))'),
    (PYTHON, 'api.executeBehavior("GO_TO_POINT", relative_coordinates=[13, -13, 0])'),
    (PYTHON, 'api.executeBehavior("FOLLOW_PATH", path=[[5, 0, 6], [13, -13, 6]])'),
    (AEROSTACK2, "uav.go_to(13, -13, 6, 1.0)"),  # positional
    (AEROSTACK2, "uav.go_to.go_to_point([13, -13, 6], speed=1.0)"),
], ids=["coordinates=", "point=", "any case", "relative", "a path", "go_to(x, y, z)", "go_to_point(point)"])
def test_every_way_a_python_mission_gives_a_destination_is_checked_against_the_safety_rules(
        tmp_path, capsys, source, call):
    rules = write(tmp_path / "rules.yaml", KEEP_OUT)
    mission = tmp_path / "m.py"
    mission.write_text(source.format(call=call))
    line = source.splitlines().index("{call}" if "{call}" in source.splitlines() else "    {call}") + 1
    assert main(["verify", str(mission), "--safety-rules", str(rules)]) == 1
    out = capsys.readouterr().out
    assert f"{mission}:{line}: error: the destination (13, -13, 6)" in out and "keep_out_tower" in out
    elsewhere = tmp_path / "elsewhere.py"
    elsewhere.write_text(source.format(call=call.replace("13, -13", "5, -5").replace("13, -13, 0", "5, -5, 0")))
    assert main(["verify", str(elsewhere), "--safety-rules", str(rules)]) == 0, capsys.readouterr().out
