"""Safety monitors on the simulator: each rule watched every tick, its contingency taken at the moment it breaks."""

from __future__ import annotations

import json
import math
import textwrap

import aeroexec.engine.api as api
import pytest
from aeroexec.cli.main import main
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.config import SimConfig
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.catalog.safety_rules import read_safety_rules_text
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety.declared import vocabulary


def engine_with(rules: str, config: SimConfig) -> tuple[Engine, SimulatedDrone]:
    catalog = default_catalog()
    found = read_safety_rules_text(textwrap.dedent(rules), "rules.yaml", vocabulary(catalog))
    assert not found.problems, found.problems
    drone = SimulatedDrone(config=config)
    return Engine(drone, catalog=catalog.with_safety_rules(found.rules)), drone


def patrol() -> None:
    api.execute_behavior("TAKE_OFF", ALTITUDE=13)
    for point in [(15, 0, 13), (15, 15, 13), (-15, 15, 13), (-15, -15, 13), (15, -15, 13)] * 4:
        if api.execute_behavior("GO_TO_POINT", COORDINATES=list(point)) != "GOAL_ACHIEVED":
            api.execute_behavior("GO_TO_POINT", COORDINATES=list(point))  # once more: a safety rule refuses it
            return


def test_the_return_margin_sends_the_drone_home_when_reached_and_it_lands_with_it():
    engine, drone = engine_with("""\
        - rule: return_margin
          always: return_margin(self, ?m), ?m >= 20
          contingency: return
        """, SimConfig(initial_battery_percent=45, battery_hover_minutes=3))
    engine.run(patrol, max_time=600)
    assert engine.run_until(lambda: not drone.telemetry().armed, 120)
    (violation,) = engine.log.events("safety_violated")
    assert violation.data["rule"] == "return_margin" and 19.0 <= float(violation.data["beliefs"]["?m"]) < 20.0
    home = [e for e in engine.log.events("activated") if e.data.get("source") == "safety"]
    assert home[0].time == violation.time and home[0].data["arguments"]["COORDINATES"][:2] == [0.0, 0.0]
    telemetry = drone.telemetry()
    assert math.hypot(*telemetry.position[:2]) < 1.0, "it landed at home"
    assert 18.5 <= telemetry.battery_percent <= 22.0, "it landed with the margin it kept"
    refused = [e for e in engine.log.events("failed_preconditions") if "has taken over" in e.detail]
    assert refused, "the mission cannot take the drone back"


def test_link_loss_lands_within_the_stated_time():
    engine, drone = engine_with("""\
        - rule: link_loss
          within: 30
          after: communication(wireless, lost)
          ensure: flight_state(self, landed)
          contingency: land
        """, SimConfig(link_loss=(15.0, 200.0)))
    engine.run(patrol, max_time=120)
    assert engine.run_until(lambda: not drone.telemetry().armed, 60)
    (triggered,) = engine.log.events("safety_triggered")
    (met,) = engine.log.events("safety_met")
    landed = engine.log.events("drone_landed")[0]
    assert 15.0 <= triggered.time <= 15.2 and landed.time - triggered.time < 30.0
    assert met.data["seconds"] < 30.0 and not engine.log.events("safety_violated")


def test_a_keep_out_rule_holds_the_drone_at_the_boundary(tmp_path, capsys):
    mission = tmp_path / "keepout.xml"
    mission.write_text("""<root BTCPP_format="4" main_tree_to_execute="M">
  <SafetyRules><![CDATA[
    - rule: keep_out_pad
      never: stopping_point(self, ?p), distance(?p, (10, -10, 6), ?d), ?d < 4
      contingency: hold
  ]]></SafetyRules>
  <BehaviorTree ID="M">
    <Sequence>
      <TAKE_OFF ALTITUDE="6"/>
      <GO_TO_POINT COORDINATES="16, -16, 6"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
""")
    assert main(["run", str(mission), "--quiet", "--output", str(tmp_path / "out")]) == 1  # it did not arrive
    records = [json.loads(line) for line in (tmp_path / "out" / "events.jsonl").read_text().splitlines()]
    (violation,) = [r for r in records if r["kind"] == "safety_violated"]
    assert violation["data"]["rule"] == "keep_out_pad" and "?d" in violation["data"]["beliefs"]
    path = [r["belief"] for r in records if r["kind"] == "belief_added" and r["belief"].startswith("position(self")]
    points = [tuple(float(v) for v in p[p.index("(", 9) + 1:p.rindex(")") - 1].split(",")) for p in path]
    nearest = min(math.dist(p[:2], (10, -10)) for p in points)
    assert 3.3 <= nearest <= 4.6, f"it stopped at the boundary (4 m, braking from 5 m/s), {nearest:.2f} m away"


def test_a_rule_far_from_breaking_is_hardly_checked():
    engine, _ = engine_with("""\
        - rule: far_away
          never: position(self, ?p), distance(?p, (500, 500, 5), ?d), ?d < 5
          contingency: land
        - rule: low
          never: charge(battery, ?c), ?c < 5
          contingency: land
        """, SimConfig())
    engine.run(patrol, max_time=60)
    checks = engine.safety.checks
    assert checks["far_away"] <= 3 and checks["low"] <= 3, checks


def test_a_maximum_mission_time_hands_a_tree_over_to_its_subtree_and_a_python_mission_to_its_function(
        tmp_path, capsys):
    tree = tmp_path / "timed.xml"
    tree.write_text("""<root BTCPP_format="4" main_tree_to_execute="M">
  <SafetyRules><![CDATA[
    - {rule: max_time, never: "mission_time(?t), ?t > 8", contingency: subtree GoHome}
  ]]></SafetyRules>
  <BehaviorTree ID="M">
    <Sequence><TAKE_OFF ALTITUDE="3"/><WAIT DURATION="60"/></Sequence>
  </BehaviorTree>
  <BehaviorTree ID="GoHome">
    <Sequence><GO_TO_POINT COORDINATES="0, 0, 3"/><LAND/></Sequence>
  </BehaviorTree>
</root>
""")
    assert main(["run", str(tree), "--quiet", "--output", str(tmp_path / "t")]) != 0  # its mission did not finish
    records = [json.loads(line) for line in (tmp_path / "t" / "events.jsonl").read_text().splitlines()]
    (violation,) = [r for r in records if r["kind"] == "safety_violated"]
    assert 8.0 < violation["time"] < 8.5 and "handed over to subtree GoHome" in violation["detail"]
    landed = [r for r in records if r["kind"] == "drone_landed"]
    assert landed and landed[0]["time"] < 30, "the subtree landed it, long before the WAIT would have ended"
    assert main(["report", str(tmp_path / "t" / "events.jsonl")]) == 0
    page = (tmp_path / "t" / "report.html").read_text()
    assert "<h2>Safety rules</h2>" in page and "max_time" in page and "violated" in page
    python = tmp_path / "timed.py"
    python.write_text('''from aeroexec.engine.api import execute_behavior

SAFETY_RULES = """
- {rule: max_time, never: "mission_time(?t), ?t > 8", contingency: call go_home}
"""


def go_home():
    execute_behavior("LAND")


def mission():
    execute_behavior("TAKE_OFF", ALTITUDE=3)
    execute_behavior("WAIT", DURATION=60)
''')
    assert main(["run", str(python), "--quiet", "--output", str(tmp_path / "p")]) == 1
    records = [json.loads(line) for line in (tmp_path / "p" / "events.jsonl").read_text().splitlines()]
    kinds = [r["kind"] for r in records]
    assert "mission_preempted" in kinds and kinds.index("mission_preempted") < kinds.index("drone_landed")
    landing = next(r for r in records if r["kind"] == "activated" and r["behavior"] == "LAND")
    assert landing["data"]["source"] == "mission" and 8.0 < landing["time"] < 9.0


def test_a_called_contingency_stops_what_the_mission_was_waiting_on(tmp_path, capsys):
    python = tmp_path / "timed.py"
    python.write_text('''from aeroexec.engine.api import execute_behavior

SAFETY_RULES = """
- {rule: max_time, never: "mission_time(?t), ?t > 8", contingency: call go_home}
"""


def go_home():
    execute_behavior("GO_TO_POINT", COORDINATES=[0, 0, 3])
    execute_behavior("WAIT", DURATION=5)
    execute_behavior("LAND")


def mission():
    execute_behavior("TAKE_OFF", ALTITUDE=3)
    execute_behavior("GO_TO_POINT", COORDINATES=[4, 0, 3])
    execute_behavior("WAIT", DURATION=60)
''')
    assert main(["run", str(python), "--quiet", "--output", str(tmp_path / "p")]) == 1
    records = [json.loads(line) for line in (tmp_path / "p" / "events.jsonl").read_text().splitlines()]
    (violation,) = [r for r in records if r["kind"] == "safety_violated"]
    waits = [r for r in records if r.get("behavior") == "WAIT" and r["kind"] in ("INTERRUPTED", "GOAL_ACHIEVED")]
    assert waits[0]["kind"] == "INTERRUPTED" and waits[0]["time"] == violation["time"], "the mission's WAIT stopped"
    assert "safety rule max_time" in waits[0]["detail"]
    assert waits[1]["kind"] == "GOAL_ACHIEVED", "the function's own WAIT ran, its behavior free again"
    landed = [r for r in records if r["kind"] == "drone_landed"]
    assert landed and landed[0]["time"] < 30 and math.hypot(*landed[0]["data"]["position"][:2]) < 1.0


FENCED = '''import aeroexec.engine.api as api

SAFETY_RULES = """
- rule: fence
  always: position(self, (?x, ?y, ?z)), ?x > -10, ?x < 10, ?y > -10, ?y < 10
  contingency: {contingency}
"""


def mission():
    api.execute_behavior("TAKE_OFF", altitude=5)
    ok, here = api.consult_belief("position(self, (?x, ?y, ?z))")
    api.execute_behavior("GO_TO_POINT", coordinates=[here["x"] + 15, here["y"], 5])  # out through the fence
    api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, 5])  # refused: the rule has the drone
    api.execute_behavior("LAND")  # refused too: the mission ends at once, the contingency under way
'''


@pytest.mark.parametrize("contingency", ["hold", "return home", "land"])
def test_a_broken_rule_fails_the_run_and_its_end_never_undoes_a_hold_or_a_return(tmp_path, capsys, contingency):
    """The run did not do what was asked: failed, exit 1, the last line naming the rule (not "completed with
    refused requests", exit 3); a hold lands inside the fence, a return at home, though the mission ended first."""
    mission = tmp_path / "fenced.py"
    mission.write_text(FENCED.format(contingency=contingency))
    assert main(["run", str(mission), "--quiet", "--output", str(tmp_path / "out")]) == 1
    summary = capsys.readouterr().err.strip().splitlines()
    assert "fenced.py: failed at" in summary[-2] and "safety rule fence broken at t=" in summary[-1], summary
    records = [json.loads(line) for line in (tmp_path / "out" / "events.jsonl").read_text().splitlines()]
    kinds = [r["kind"] for r in records]
    assert kinds.index("safety_violated") < kinds.index("mission_completed"), "the mission ended during it"
    (landed,) = [r for r in records if r["kind"] == "drone_landed"]
    x, y, _ = landed["data"]["position"]
    if contingency == "hold":
        assert abs(x) < 10 and abs(y) < 10, f"it landed where it held, inside the fence, not at ({x:.2f}, {y:.2f})"
    elif contingency == "return home":
        assert math.hypot(x, y) < 1.0, f"it landed at home, where it returned, not at ({x:.2f}, {y:.2f})"
    (ended,) = [r for r in records if r["kind"] == "run_ended"]
    assert ended["detail"] == "failed" and ended["data"]["exit_status"] == 1
    assert ended["data"]["reasons"][0].startswith("safety rule fence broken at t=")
