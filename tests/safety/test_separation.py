"""Two fleet drones on crossing routes keep their separation: each watches the other's shared position
(``position(dN, P)`` over the fleet link) with a separation rule, and the one that would close in holds."""

from __future__ import annotations

import json
import math

from aeroexec.cli.main import main

MISSION = '''from aeroexec.engine.api import execute_behavior

SAFETY_RULES = """
- rule: separation
  never: stopping_point(self, ?p), position(?o, ?q), ?o != self, distance(?p, ?q, ?d), ?d < 8
  contingency: hold
"""


def mission():
    execute_behavior("TAKE_OFF", ALTITUDE=5)
    execute_behavior("GO_TO_POINT", COORDINATES={point})
    execute_behavior("LAND")
'''


def track(path) -> dict[float, tuple]:
    """The drone's own positions by time, from its event log."""
    found = {}
    for line in path.read_text().splitlines():
        record = json.loads(line)
        belief = record.get("belief", "")
        if record["kind"] == "belief_added" and belief.startswith("position(self"):
            found[round(record["time"], 2)] = tuple(float(v) for v in belief[16:-2].split(","))
    return found


def test_two_fleet_drones_on_crossing_routes_keep_the_separation(tmp_path, capsys):
    (tmp_path / "cross1.py").write_text(MISSION.format(point=[12, 0, 5]))
    (tmp_path / "cross2.py").write_text(MISSION.format(point=[0, 12, 5]))
    fleet = tmp_path / "cross.yaml"
    fleet.write_text("fleet: cross\ndrones:\n  - {name: d1, mission: cross1.py, home: [-12, 0]}\n"
                     "  - {name: d2, mission: cross2.py, home: [0, -12]}\n")
    main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "out")])
    violations = [json.loads(line) for drone in ("d1", "d2")
                  for line in (tmp_path / "out" / drone / "events.jsonl").read_text().splitlines()
                  if '"safety_violated"' in line]
    assert violations and all(v["data"]["rule"] == "separation" for v in violations)
    one, two = track(tmp_path / "out" / "d1" / "events.jsonl"), track(tmp_path / "out" / "d2" / "events.jsonl")
    closest = min(math.dist(one[t], two[t]) for t in one.keys() & two.keys())
    assert closest >= 3.0, f"they came {closest:.1f} m apart"
    # without the rule, the same routes meet at the crossing
    for name in ("cross1.py", "cross2.py"):
        path = tmp_path / name
        path.write_text(path.read_text().replace("SAFETY_RULES", "NO_RULES"))
    main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / "bare")])
    one, two = track(tmp_path / "bare" / "d1" / "events.jsonl"), track(tmp_path / "bare" / "d2" / "events.jsonl")
    assert min(math.dist(one[t], two[t]) for t in one.keys() & two.keys()) < 3.0


def test_verify_refuses_fleet_routes_that_cross_within_the_separation(tmp_path, capsys):
    for name, point in (("cross1.py", [12, 0, 5]), ("cross2.py", [0, 12, 5])):
        (tmp_path / name).write_text(MISSION.format(point=point).replace("SAFETY_RULES", "NO_RULES"))
    rules = tmp_path / "separation.yaml"
    rules.write_text("- rule: separation\n  never: position(self, ?p), position(?o, ?q), ?o != self, "
                     "distance(?p, ?q, ?d), ?d < 3\n  contingency: hold\n")
    fleet = tmp_path / "cross.yaml"
    fleet.write_text("fleet: cross\ndrones:\n  - {name: d1, mission: cross1.py, home: [-12, 0]}\n"
                     "  - {name: d2, mission: cross2.py, home: [0, -12]}\n")
    assert main(["verify", str(fleet), "--safety-rules", str(rules)]) == 1
    out = capsys.readouterr().out
    assert f"{tmp_path / 'cross1.py'}:12: error: the routes of d1 and d2 come" in out
    assert f"safety rule separation ({rules}:1)" in out
    fleet.write_text(fleet.read_text().replace("home: [0, -12]", "home: [0, -18]"))  # d2 crosses well after d1
    assert main(["verify", str(fleet), "--safety-rules", str(rules)]) == 0


VELOCITIES = "stopping_point(self, ?p), position(?o, ?), ?o != self, stopping_point(?o, ?q), distance(?p, ?q, ?d)"
POSITIONS = "stopping_point(self, ?p), position(?o, ?q), ?o != self, distance(?p, ?q, ?d)"


def closest_with(tmp_path, condition: str, name: str) -> float:
    rule = f'- {{rule: separation, never: "{condition}, ?d < 4", contingency: hold}}\n'
    for drone, point in (("cross1.py", [12, 0, 5]), ("cross2.py", [0, 12, 5])):
        (tmp_path / drone).write_text(MISSION.format(point=point).replace(MISSION.split('"""')[1], "\n" + rule))
    fleet = tmp_path / "cross.yaml"
    fleet.write_text("fleet: cross\ndrones:\n  - {name: d1, mission: cross1.py, home: [-12, 0]}\n"
                     "  - {name: d2, mission: cross2.py, home: [0, -12]}\n")
    main(["fleet", str(fleet), "--quiet", "--output", str(tmp_path / name)])
    one, two = track(tmp_path / name / "d1" / "events.jsonl"), track(tmp_path / name / "d2" / "events.jsonl")
    return min(math.dist(one[t], two[t]) for t in one.keys() & two.keys())


def test_with_the_mates_shared_velocities_a_separation_rule_needs_no_lookahead(tmp_path, capsys):
    """The fleet link writes each mate's velocity (velocity(dN, V)) with its position, so a rule compares where
    both drones would stop: 4 m between the stopping points keeps them apart; the same 4 m against the mate's
    position alone does not (it would need a larger distance, a lookahead, to make up for the mate's motion)."""
    assert closest_with(tmp_path, VELOCITIES, "both") >= 3.0
    assert closest_with(tmp_path, POSITIONS, "own") < 3.0
