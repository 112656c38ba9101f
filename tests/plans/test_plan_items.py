"""QGroundControl plans (.plan) as behavior trees: the documented JSON read in both item forms, positions as
geographic points placed from the home the drone flies from, the geofence checked against the flights, items without
a behavior reported with their number and line, DO_JUMP as a Repeat, camera triggers beside the items, the converted
tree written as BehaviorTree.CPP v4 XML that BehaviorTree.CPP loads, and survey.plan flown."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import behaviortreepy as bt
import pytest
from aeroexec.drones.geodesy import enu_to_geodetic, geo_to_enu, parse_geo
from aeroexec.drones.sim import default_world
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees.groot.btlog import read_btlog
from aeroexec.trees.items import items_document
from aeroexec.trees.items.plan import read_plan
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.loaders.xml_writer import write_xml
from aeroexec.trees.mission_file import read_mission_tree
from aeroexec.trees.model import TreeFormatError

ROOT = Path(__file__).parents[2]
SURVEY = ROOT / "missions" / "survey.plan"
HOME = default_world().home


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)


def latlon(x: float, y: float) -> list[float]:
    lat, lon, _ = enu_to_geodetic((x, y, 0.0), HOME)
    return [lat, lon]


def item(command: int, params: list, frame: int = 3) -> dict:
    return {"autoContinue": True, "command": command, "doJumpId": 1, "frame": frame, "params": params,
            "type": "SimpleItem"}


def waypoint(x: float, y: float, z: float, hold: float = 0, yaw: float | None = None, command: int = 16) -> dict:
    return item(command, [hold, 0, 0, yaw, *latlon(x, y), z])


def plan(*items: dict, fence: dict | None = None, rally: list | None = None, home: list | None = None) -> str:
    document = {"fileType": "Plan", "groundStation": "QGroundControl", "version": 1,
                "mission": {"cruiseSpeed": 15, "firmwareType": 12, "globalPlanAltitudeMode": 1, "hoverSpeed": 5,
                            "items": list(items), "plannedHomePosition": home or list(HOME), "vehicleType": 2,
                            "version": 2},
                "geoFence": fence or {"circles": [], "polygons": [], "version": 2},
                "rallyPoints": {"points": rally or [], "version": 2}}
    return json.dumps(document, indent=4)


def tree(text: str, file: str = "m.plan", home=None):
    return read_mission_tree(text, file, home)


def leaves(document) -> list[tuple[str, str, dict]]:
    return [(n.type, n.name, n.ports) for n in document.root.children]


def enu(port: str, home=HOME) -> tuple[float, ...]:
    return tuple(round(v, 2) for v in geo_to_enu(parse_geo(port), home))


def takeoff(z: float = 5) -> dict:
    return item(22, [0, 0, 0, None, *latlon(0, 0), z])


def test_the_survey_plan_is_a_tree_of_catalog_behaviors_at_geographic_points():
    document = tree(SURVEY.read_text(), str(SURVEY))
    assert not [p for p in document.problems if p.severity == "error"]
    nodes = leaves(document)
    assert nodes[0] == ("TAKE_OFF", "item 1 TAKEOFF", {"ALTITUDE": "15"})
    assert nodes[1][0] == "LOOK_AT_A_POINT" and enu(nodes[1][2]["COORDINATES"]) == (8, 8, 10)
    assert enu(nodes[2][2]["POINT_TO_LOOK_DURING_FLIGHT"]) == (8, 8, 10)  # the ROI until DO_SET_ROI_NONE (item 5)
    camera = next(n for n in document.root.children if n.type == "Parallel")
    body, trigger = camera.children
    assert (trigger.type, trigger.ports) == ("TRIGGER_CAMERA", {"DISTANCE": "5"})  # DO_SET_CAM_TRIGG_DIST 5 m
    survey = [n for n in body.children if n.type == "GO_TO_POINT"]
    assert len(survey) == 10 and all(n.ports["SPEED"] == "4" for n in survey)  # DO_CHANGE_SPEED item 2
    assert [enu(n.ports["COORDINATES"]) for n in survey[:3]] == [(-10, -10, 15), (10, -10, 15), (10, -5, 15)]
    assert "POINT_TO_LOOK_DURING_FLIGHT" not in survey[0].ports
    assert [n[0] for n in nodes].count("TAKE_PHOTO") == 2  # IMAGE_START_CAPTURE of one, the trigger's first shot
    assert nodes[-1][0] == "LAND" and nodes[-2] == ("WAIT", "item 19 loiter", {"DURATION": "3"})
    assert [f.kind for f in document.fences] == ["inclusion polygon", "exclusion circle"]
    assert document.rally_points[0] == pytest.approx((-15, -15, 10), abs=0.01)
    lines = SURVEY.read_text().splitlines()
    assert '"command": 22' in "".join(lines[document.root.children[0].line - 1:document.root.children[0].line + 5])


def test_the_older_item_form_coordinate_and_four_params_reads_as_the_newer_one():
    newer = waypoint(3, 4, 6, hold=2)
    older = {k: v for k, v in newer.items() if k != "params"} | {"params": [2, 0, 0, None],
                                                                  "coordinate": [*latlon(3, 4), 6]}
    assert leaves(tree(plan(takeoff(), newer))) == leaves(tree(plan(takeoff(), older)))
    assert enu(leaves(tree(plan(takeoff(), older)))[1][2]["COORDINATES"]) == (3, 4, 6)


def test_a_plan_flies_the_same_latitudes_and_longitudes_from_another_home():
    moved = (HOME[0], HOME[1] + 0.0001, HOME[2] + 10)  # about 7.5 m east, 10 m higher
    here = item(22, [0, 0, 0, None, None, None, 5])  # take off where the drone is
    document = tree(plan(here, waypoint(0, 0, 5), item(16, [0, 0, 0, None, *latlon(3, 4), 498], 0)), home=moved)
    first, second = (n.ports["COORDINATES"] for n in document.root.children if n.type == "GO_TO_POINT")
    assert enu(first, moved) == pytest.approx((-7.55, 0, 5), abs=0.02)
    assert parse_geo(second)[2] == 0  # MAV_FRAME_GLOBAL: 498 m above sea level is this home's altitude
    assert any("m from the home it flies from" in p.message and p.severity == "warning" for p in document.problems)


def test_values_out_of_their_domain_are_errors_at_their_line():
    bad_home = plan(takeoff(), home=[121.0, 8.5, 400])
    problems = read_plan(bad_home, "h.plan").problems
    assert [p.severity for p in problems] == ["error"] and '"mission"' in bad_home.splitlines()[problems[0].line - 1]
    assert "latitude 121 is not between -90 and 90" in problems[0].message
    below = tree(plan(takeoff(), item(16, [0, 0, 0, None, *latlon(3, 4), 400], 0)))
    (error,) = [p for p in below.problems if p.severity == "error"]
    assert error.message == "item 2: NAV_WAYPOINT at 400 m above sea level is below home (488 m above sea level)"


def test_items_without_a_behavior_are_reported_with_their_number_and_line_never_dropped(tmp_path):
    text = plan(takeoff(), item(183, [1, 1500, 0, 0, 0, 0, 0], 2), item(84, [0, 0, 0, None, *latlon(1, 1), 5]),
                waypoint(1, 2, 5) | {"frame": 1}, {"type": "ComplexItem", "complexItemType": "fwLanding"},
                item(201, [1, 0, 0, 0, 0, 0, 0], 2), waypoint(2, 2, 5), item(22, [0, 0, 0, None, None, None, None]))
    path = tmp_path / "odd.plan"
    path.write_text(text)
    result = aeroexec("verify", str(path))
    assert result.returncode == 1
    out = result.stdout
    for number, what in ((2, "DO_SET_SERVO moves a servo aeroexec does not drive"), (3, "NAV_VTOL_TAKEOFF is a VTOL"),
                         (4, "MAV_FRAME 1"), (5, "a fixed-wing landing pattern"), (6, "MAV_ROI mode 1"),
                         (8, "NAV_TAKEOFF without an altitude")):
        line = next(ln for ln in out.splitlines() if f"item {number}:" in ln)
        assert what in line and line.startswith(f"{path}:") and ": error:" in line
    assert "6 errors" in out
    run = aeroexec("run", str(path), "--plain", "--output", str(tmp_path / "out"))
    assert run.returncode == 1 and "will not fly" in run.stderr and "takeoff" not in run.stdout.lower()


@pytest.mark.parametrize("text, message, line", [
    ('{"fileType": "Plan",\n "mission": {"items": [}', "not JSON", 2),
    ('{"fileType": "Mission", "mission": {}}', '"fileType" must be "Plan"', 1),
])
def test_a_file_that_is_not_a_plan_is_refused_at_its_line(text, message, line):
    with pytest.raises(TreeFormatError) as caught:
        read_plan(text, "bad.plan")
    (file, at, problem), = caught.value.problems
    assert file == "bad.plan" and at == line and message in problem


def test_an_empty_fence_is_no_fence_and_a_fence_of_two_points_an_error_at_its_line():
    empty = json.loads(plan(takeoff(), waypoint(1, 1, 5)))
    empty["geoFence"] = {"polygon": [], "version": 1}  # QGroundControl's "no fence"
    assert not [p for p in tree(json.dumps(empty)).problems if p.severity == "error"]
    broken = plan(takeoff(), fence={"version": 2, "polygons": [{"inclusion": True, "polygon": [[1, 2], [1, 3]]}]})
    (error,) = read_plan(broken, "f.plan").problems
    assert "3 or more" in error.message and error.line > 1


def test_return_to_launch_goes_to_the_nearest_rally_point_and_speed_and_yaw_follow_mavlink():
    text = plan(takeoff(4), item(178, [1, 2, -1, 0, 0, 0, 0], 2), waypoint(8, 8, 4, hold=2, yaw=0),
                item(178, [1, -2, -1, 0, 0, 0, 0], 2), waypoint(9, 9, 4, yaw=90), item(20, [0] * 7, 2),
                rally=[[*latlon(10, 10), 6]])
    nodes = leaves(tree(text))
    assert {k: v for k, v in nodes[1][2].items() if k != "COORDINATES"} == {"SPEED": "2", "YAW_ANGLE_AT_THE_END": "90"}
    assert nodes[2] == ("WAIT", "item 3 hold", {"DURATION": "2"})
    assert nodes[3][2].keys() == {"COORDINATES", "YAW_ANGLE_AT_THE_END"}  # -2: the vehicle's own speed again
    assert nodes[3][2]["YAW_ANGLE_AT_THE_END"] == "0"  # east
    assert enu(nodes[4][2]["COORDINATES"]) == (10, 10, 4) and nodes[5][0] == "LAND"


def test_do_jump_repeats_the_items_it_jumps_back_over_warns_of_forever_and_refuses_forward_jumps():
    jump = plan(takeoff(), waypoint(1, 0, 5), waypoint(2, 0, 5), item(177, [2, 2, 0, 0, 0, 0, 0], 2),
                item(20, [0] * 7, 2))
    nodes = tree(jump).root.children
    assert [n.type for n in nodes] == ["TAKE_OFF", "Repeat", "GO_TO_POINT", "LAND"]
    assert nodes[1].ports == {"num_cycles": "3"} and [c.name for c in nodes[1].children[0].children] == \
        ["item 2 WAYPOINT", "item 3 WAYPOINT"]
    forever = tree(plan(takeoff(), waypoint(1, 0, 5), item(177, [2, -1, 0, 0, 0, 0, 0], 2)))
    assert any("repeats forever" in p.message and p.message.startswith("item 3:") and p.severity == "warning"
               for p in forever.problems)
    ahead = tree(plan(takeoff(), item(177, [3, 1, 0, 0, 0, 0, 0], 2), waypoint(1, 0, 5)))
    assert any("not before it" in p.message and p.severity == "error" for p in ahead.problems)


def test_a_survey_without_items_computes_its_transects_as_qgroundcontrol_did():
    real = Path(__file__).with_name("data") / "real_missions" / "mavsdk"
    generated = json.loads((real / "qgroundcontrol_sample_with_survey_missing_items.plan").read_text())
    survey = generated["mission"]["items"][1]
    ours = tree(json.dumps(generated)).root
    flights = [n.ports["COORDINATES"] for n in ours.walk() if n.type == "GO_TO_POINT"]
    assert len(flights) == 8 == len(survey["TransectStyleComplexItem"]["VisualTransectPoints"])
    for port, (lat, lon) in zip(flights, survey["TransectStyleComplexItem"]["VisualTransectPoints"], strict=True):
        got = parse_geo(port)
        assert got[:2] == pytest.approx((lat, lon), abs=1e-7)  # QGroundControl's own points, to 1 cm
        assert got[2] == 50
    cameras = [n for n in ours.walk() if n.type == "TRIGGER_CAMERA"]
    assert [c.ports for c in cameras] == [{"DISTANCE": "25"}]  # CameraTriggerInTurnAround: through the turns


def test_convert_writes_btcpp_xml_that_we_read_back_and_behaviortree_cpp_loads_and_ticks(tmp_path):
    out = tmp_path / "survey.xml"
    result = aeroexec("convert", str(SURVEY), "--to", "xml", "-o", str(out))
    assert result.returncode == 0, result.stderr
    text = out.read_text()
    original = tree(SURVEY.read_text(), str(SURVEY))
    again = read_xml(text, str(out))
    assert [(n.type, n.name, n.ports) for n in again.root.walk()] == \
        [(n.type, n.name, n.ports) for n in original.root.walk()]
    verified = aeroexec("verify", str(out), "--home", f"{HOME[0]},{HOME[1]},{HOME[2]}")
    assert verified.returncode == 0, verified.stdout
    # BehaviorTree.CPP (behaviortreepy) with the palette's leaves registered; behaviortreepy cannot declare ports
    # from Python, so their port attributes are handed over as _attributes, which BT.CPP passes over
    root = ElementTree.fromstring(text)
    palette = {m.get("ID") for m in root.find("TreeNodesModel")}
    assert palette == {"TAKE_OFF", "LOOK_AT_A_POINT", "GO_TO_POINT", "TAKE_PHOTO", "TRIGGER_CAMERA", "WAIT", "LAND"}
    for element in root.iter():
        if element.tag in palette and "ID" not in element.attrib:
            for key in [k for k in element.attrib if k != "name"]:
                element.set(f"_{key}", element.attrib.pop(key))
    ticked: list[str] = []
    factory = bt.BehaviorTreeFactory()
    for kind in palette:  # the camera trigger runs beside its items until they are done, as in flight
        factory.register_simple_stateful_action(kind, lambda n: (ticked.append(n.name()), "RUNNING")[1],
                                                (lambda n: "RUNNING") if kind == "TRIGGER_CAMERA" else
                                                (lambda n: "SUCCESS"), lambda n: None)
    bt_tree = factory.create_tree_from_text(ElementTree.tostring(root, encoding="unicode"))
    status = bt.NodeStatus.RUNNING
    for _ in range(400):
        status = bt_tree.tick_exactly_once()
        if status != bt.NodeStatus.RUNNING:
            break
    assert status == bt.NodeStatus.SUCCESS
    assert sorted(ticked) == sorted(n.name for n in original.root.walk() if n.type in palette)
    trigger = ticked.index("item 7 TRIGGER_CAMERA")  # started beside the first of its items
    assert ticked[trigger - 1] == "item 8 WAYPOINT"


def test_convert_refuses_a_plan_with_errors_and_writes_nothing(tmp_path):
    path = tmp_path / "servo.plan"
    path.write_text(plan(takeoff(), item(183, [1, 1500, 0, 0, 0, 0, 0], 2)))
    result = aeroexec("convert", str(path), "-o", str(tmp_path / "servo.xml"))
    assert result.returncode == 1 and "item 2: DO_SET_SERVO moves a servo" in result.stderr
    assert "nothing written" in result.stderr and not (tmp_path / "servo.xml").exists()


def test_the_survey_plan_flies_to_completion_on_the_simulator(tmp_path):
    result = aeroexec("run", str(SURVEY), "--plain", "--output", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "survey.plan: completed" in result.stderr
    arrived = [line for line in result.stdout.splitlines() if "drone_arrived" in line]
    for x, y in ((-10, -10), (10, -10), (10, -5), (-10, -5), (-10, 0), (10, 0), (10, 5), (-10, 5), (-10, 10),
                 (10, 10)):
        assert any(f"at ({x:.1f}, {y:.1f}, 15.0)" in line for line in arrived), (x, y)
    photos = len(list(tmp_path.glob("photo_*.png")))
    assert 2 + 120 // 5 - 1 <= photos <= 2 + 120 // 5 + 2  # two single photos, one every 5 m of the 120 m survey
    assert "drone_landed" in result.stdout
    log = read_btlog(tmp_path / "mission.btlog")  # Groot2's replay of the plan's tree
    assert log.subtrees() == [("survey", "")]
    assert [(t.uid, t.status_name) for t in log.transitions[-2:]] == [(1, "SUCCESS"), (1, "IDLE")]
    assert write_xml(tree(SURVEY.read_text(), str(SURVEY)), default_catalog()).count("<GO_TO_POINT") == 12


def test_verify_and_run_place_the_plan_in_the_world_given(tmp_path):
    world = (ROOT / "drones" / "sim" / "default_world.yaml").read_text()
    moved = world.replace("home: {lat: 47.397742,", "home: {lat: 47.396842,")  # 100 m further south
    assert moved != world
    (tmp_path / "south.yaml").write_text(moved)
    result = aeroexec("verify", str(SURVEY), "--world", str(tmp_path / "south.yaml"))
    assert result.returncode == 1
    assert "the mission's home is 100 m from the home it flies from" in result.stdout
    out_of_range = [ln for ln in result.stdout.splitlines() if "WRONG_VALUE" in ln and "COORDINATES" in ln]
    assert out_of_range and all(ln.startswith(f"{SURVEY}:") and ": item " in ln for ln in out_of_range)
    assert all("outside the world's bounds (x -20..20, y -20..20, z 0..20; geofence)" in ln for ln in out_of_range)


def test_convert_writes_yaml_trees_as_xml_and_refuses_tml(tmp_path):
    out = tmp_path / "patrol.xml"
    assert aeroexec("convert", str(ROOT / "missions" / "square_patrol.yaml"), "-o", str(out)).returncode == 0
    assert '<SubTree ID="Square" />' in out.read_text() and aeroexec("verify", str(out)).returncode == 0
    tml = aeroexec("convert", str(ROOT / "missions" / "search_for_object.tml.xml"))
    assert tml.returncode == 1 and "a TML mission does not convert" in tml.stderr and not tml.stdout


def test_items_document_needs_no_world_for_a_mission_with_its_own_home():
    from aeroexec.trees.items.readers import read_item_mission

    document = items_document(read_item_mission(plan(takeoff(), waypoint(3, 4, 5)), "h.plan"))
    assert document.home == pytest.approx(HOME)
    assert enu(document.root.children[1].ports["COORDINATES"]) == (3, 4, 5)
    assert math.isclose(len(document.root.children), 2)
