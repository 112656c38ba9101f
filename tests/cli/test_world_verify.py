"""``aeroexec verify`` checks literal destinations and paths against the world (issue 18, point 3): the bounds
(geofence) and the obstacle clearance the catalog's preconditions ask, naming the obstacle and the distance;
in flight, a failed clearance precondition names the obstacle too."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

from aeroexec.cli.main import main
from fleet_parts import fleet_files

PYTHON = '''
import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    api.execute_behavior("GO_TO_POINT", coordinates=(5, 5, 3))
    api.execute_behavior("GO_TO_POINT", coordinates=(30, 0, 3))
    api.execute_behavior("FOLLOW_PATH", path=[(0, 0, 3), (0, 25, 3)])
    api.execute_behavior("GO_TO_POINT", coordinates=(-2, -2, 3))
    api.execute_behavior("LAND")
'''

TREE = '''<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <TAKE_OFF/>
      <GO_TO_POINT COORDINATES="5, 5, 3"/>
      <LAND/>
    </Sequence>
  </BehaviorTree>
</root>
'''

WORLD = '''
name: narrow
home: {lat: 40.0, lon: -3.0, alt: 600}
bounds: {min: [-5, -5, 0], max: [5, 5, 10]}
obstacles:
  - {name: mast, type: cylinder, center: [2, 0], radius: 0.5, height: 8}
'''


def verify(capsys, *args: str) -> tuple[int, list[str]]:
    status = main(["verify", *args])
    return status, capsys.readouterr().out.splitlines()


def test_verify_refuses_destinations_the_world_refuses_naming_obstacle_and_distance(tmp_path, capsys):
    path = tmp_path / "near.py"
    path.write_text(PYTHON)
    status, lines = verify(capsys, str(path))
    assert status == 1
    assert any(line.startswith(f"{path}:7:") and "(5, 5, 3) is 2.1 m from tower; GO_TO_POINT needs 3 m" in line
               for line in lines), lines
    assert any(line.startswith(f"{path}:8:") and "(30, 0, 3) is outside the world's bounds" in line
               and "geofence" in line for line in lines), lines
    assert any(line.startswith(f"{path}:9:") and "(0, 25, 3) is outside" in line and "PATH" in line
               for line in lines), lines
    assert not any(":10:" in line for line in lines)  # (-2, -2, 3) is clear and inside
    assert lines[-1].endswith("3 errors, 0 warnings; will not fly")
    status, lines = verify(capsys, "--no-world", str(path))
    assert status == 0 and "ready to fly" in lines[-1]


def test_verify_uses_the_world_given_and_checks_trees(tmp_path, capsys):
    tree = tmp_path / "near.xml"
    tree.write_text(TREE)
    status, lines = verify(capsys, str(tree))
    assert status == 1 and any(f"{tree}:5" in line and "from tower" in line for line in lines), lines
    world = tmp_path / "narrow.yaml"
    world.write_text(textwrap.dedent(WORLD))
    outside = tmp_path / "outside.xml"
    outside.write_text(TREE.replace("5, 5, 3", "6, 0, 3"))
    status, lines = verify(capsys, "--world", str(world), str(outside))
    assert status == 1 and any("(6, 0, 3) is outside the world's bounds (x -5..5" in line for line in lines), lines
    near_mast = tmp_path / "mast.xml"
    near_mast.write_text(TREE.replace("5, 5, 3", "3, 1, 3"))
    status, lines = verify(capsys, "--world", str(world), str(near_mast))
    assert status == 1 and any("is 0.9 m from mast; GO_TO_POINT needs 3 m" in line for line in lines), lines


def test_a_failed_clearance_precondition_in_flight_names_the_obstacle(tmp_path, capsys):
    path = tmp_path / "computed.py"
    path.write_text(textwrap.dedent('''
        import aeroexec.engine.api as api


        def mission():
            api.execute_behavior("TAKE_OFF", altitude=3)
            x = int("5")
            api.execute_behavior("GO_TO_POINT", coordinates=(x, x, 3))  # computed: verify cannot see it
            api.execute_behavior("LAND")
        '''))
    out = tmp_path / "out"
    status = main(["run", str(path), "--plain", "--output", str(out)])
    assert status == 3, capsys.readouterr().err
    records = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    refused = [r for r in records if r["kind"] == "failed_preconditions" and r["behavior"] == "GO_TO_POINT"]
    assert refused and "(5, 5, 3) is 2.1 m from tower; GO_TO_POINT needs 3 m" in refused[0]["reason"]


def test_the_example_missions_verify_against_the_default_world(capsys):
    folder = Path(__file__).parents[2] / "missions"
    missions = sorted(p for p in folder.iterdir() if p.suffix in (".py", ".xml", ".yaml")
                      and p.name != "__init__.py" and p.name not in fleet_files(folder))
    status, lines = verify(capsys, *map(str, missions))
    assert status == 0, lines


def test_tml_missions_are_checked_against_the_world_too(tmp_path, capsys):
    source = (Path(__file__).parents[2] / "missions" / "search_for_object.tml.xml").read_text()
    near = source.replace('value="[-3.0, -4.0, 3.0]"', 'value="[6.0, 6.0, 3.0]"')
    assert near != source
    path = tmp_path / "near.tml.xml"
    path.write_text(near)
    status, lines = verify(capsys, str(path))
    assert status == 1 and any("(6, 6, 3) is 0.7 m from tower; GO_TO_POINT needs 3 m" in line for line in lines)
