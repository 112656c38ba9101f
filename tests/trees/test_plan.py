"""QGroundControl plans (.plan) as behavior trees: the documented JSON converted through the world's home point,
the geofence checked against the waypoints, items without a behavior reported with their number and line, the
converted tree written as BehaviorTree.CPP v4 XML that BehaviorTree.CPP loads, and survey.plan flown."""

from __future__ import annotations

import copy
import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import behaviortreepy as bt
import pytest
from aeroexec.drones.geodesy import enu_to_geodetic
from aeroexec.drones.sim import default_world
from aeroexec.engine.catalog import default_catalog
from aeroexec.trees import TreeFormatError
from aeroexec.trees.btlog import read_btlog
from aeroexec.trees.loaders.plan_loader import read_plan
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.loaders.xml_writer import write_xml

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


def plan(*items: dict, fence: dict | None = None, rally: list | None = None) -> str:
    document = {"fileType": "Plan", "groundStation": "QGroundControl", "version": 1,
                "mission": {"cruiseSpeed": 15, "firmwareType": 12, "globalPlanAltitudeMode": 1, "hoverSpeed": 5,
                            "items": list(items), "plannedHomePosition": list(HOME), "vehicleType": 2,
                            "version": 2},
                "geoFence": fence or {"circles": [], "polygons": [], "version": 2},
                "rallyPoints": {"points": rally or [], "version": 2}}
    return json.dumps(document, indent=4)


def leaves(document) -> list[tuple[str, str, dict]]:
    return [(n.type, n.name, n.ports) for n in document.root.children]


def takeoff(z: float = 5) -> dict:
    return item(22, [0, 0, 0, None, *latlon(0, 0), z])


def test_the_survey_plan_is_a_tree_of_catalog_behaviors_placed_from_the_worlds_home():
    document = read_plan(SURVEY.read_text(), str(SURVEY))
    assert not [p for p in document.problems if p.severity == "error"]
    nodes = leaves(document)
    assert nodes[0] == ("TAKE_OFF", "item 1 TAKEOFF", {"ALTITUDE": "15"})
    survey = [n for n in nodes if n[0] == "GO_TO_POINT" and 8 <= int(n[1].split()[1]) <= 17]
    assert len(survey) == 10 and all(n[2]["SPEED"] == "4" for n in survey)  # DO_CHANGE_SPEED item 2
    assert [n[2]["COORDINATES"] for n in survey[:3]] == ["-10, -10, 15", "10, -10, 15", "10, -5, 15"]
    photos = [n for n in nodes if n[0] == "TAKE_PHOTO"]
    assert len(photos) == 12  # IMAGE_START_CAPTURE, the trigger's first shot, one per survey waypoint
    assert nodes[1] == ("LOOK_AT_A_POINT", "item 3 SET_ROI_LOCATION", {"COORDINATES": "8, 8, 10"})
    assert nodes[2][2]["POINT_TO_LOOK_DURING_FLIGHT"] == "8, 8, 10"  # the ROI until DO_SET_ROI_NONE (item 5)
    assert "POINT_TO_LOOK_DURING_FLIGHT" not in survey[0][2]
    assert nodes[-1][0] == "LAND" and nodes[-2] == ("WAIT", "item 19 loiter", {"DURATION": "3"})
    assert [f.kind for f in document.fences] == ["inclusion polygon", "exclusion circle"]
    assert document.rally_points[0] == pytest.approx((-15, -15, 10), abs=0.01)
    lines = SURVEY.read_text().splitlines()
    assert '"command": 22' in "".join(lines[document.root.children[0].line - 1:document.root.children[0].line + 5])


def test_the_same_plan_lands_elsewhere_in_a_world_with_another_home():
    moved = (HOME[0], HOME[1] + 0.0001, HOME[2] + 10)  # about 7.5 m east, 10 m higher
    here = item(22, [0, 0, 0, None, None, None, 5])  # take off where the drone is
    document = read_plan(plan(here, waypoint(0, 0, 5), item(16, [0, 0, 0, None, *latlon(3, 4), 498], 0)),
                         "m.plan", moved)
    first, second = (n.ports["COORDINATES"] for n in document.root.children if n.type == "GO_TO_POINT")
    x, y, z = (float(v) for v in first.split(","))
    assert x == pytest.approx(-7.5, abs=0.1) and y == pytest.approx(0, abs=0.01) and z == 5
    assert second.endswith(", 0")  # MAV_FRAME_GLOBAL: 498 m above sea level is this home's altitude
    assert any("m from the world's home" in p.message and p.severity == "warning" for p in document.problems)


def test_waypoints_outside_an_inclusion_fence_or_inside_an_exclusion_zone_are_errors_with_their_item_number():
    fence = {"version": 2,
             "polygons": [{"inclusion": True, "version": 1,
                           "polygon": [latlon(-10, 10), latlon(10, 10), latlon(10, -10), latlon(-10, -10)]}],
             "circles": [{"inclusion": False, "version": 1, "circle": {"center": latlon(5, 5), "radius": 2}}]}
    text = plan(takeoff(), waypoint(0, 5, 5), waypoint(15, 0, 5), waypoint(5, 6, 5), waypoint(-5, -5, 5),
                fence=fence)
    problems = read_plan(text, "fence.plan").problems
    assert [(p.severity, p.message.split(":")[0]) for p in problems] == [("error", "item 3"), ("error", "item 4")]
    assert "outside every inclusion fence" in problems[0].message and "(15, 0, 5)" in problems[0].message
    assert "inside the exclusion circle" in problems[1].message
    lines = text.splitlines()
    assert all(lines[p.line - 1].strip() == "{" and '"command": 16' in "".join(lines[p.line:p.line + 3])
               for p in problems)


def test_items_without_a_behavior_are_reported_with_their_number_and_line_never_dropped(tmp_path):
    text = plan(takeoff(), item(177, [1, 3, 0, 0, 0, 0, 0], 2), item(17, [0, 0, 0, None, *latlon(1, 1), 5]),
                waypoint(1, 2, 5) | {"frame": 1},
                {"type": "ComplexItem", "complexItemType": "StructureScan", "version": 2},
                item(201, [1, 0, 0, 0, 0, 0, 0], 2), waypoint(2, 2, 5), item(22, [0, 0, 0, None, None, None, None]))
    path = tmp_path / "odd.plan"
    path.write_text(text)
    result = aeroexec("verify", str(path))
    assert result.returncode == 1
    out = result.stdout
    for number, what in ((2, "MAV_CMD 177 (DO_JUMP)"), (3, "MAV_CMD 17 (NAV_LOITER_UNLIM)"), (4, "MAV_FRAME 1"),
                         (5, "StructureScan"), (6, "MAV_ROI mode 1"), (8, "TAKEOFF without an altitude")):
        line = next(ln for ln in out.splitlines() if f"item {number}:" in ln)
        assert what in line and line.startswith(f"{path}:") and ": error:" in line
    assert "6 errors" in out
    run = aeroexec("run", str(path), "--plain", "--output", str(tmp_path / "out"))
    assert run.returncode == 1 and "will not fly" in run.stderr and "takeoff" not in run.stdout.lower()


@pytest.mark.parametrize("text, message, line", [
    ('{"fileType": "Plan",\n "mission": {"items": [}', "not JSON", 2),
    ('{"fileType": "Mission", "mission": {}}', '"fileType" must be "Plan"', 1),
    ('{"fileType": "Plan",\n "mission": {\n "items": []}}', "at least one", 2),
    ('{"fileType": "Plan", "mission": {"items": [{}]},\n "geoFence": {"polygons": [{"polygon": [[1, 2]]}]}}',
     "3 or more", 2),
])
def test_a_file_that_is_not_a_plan_is_refused_at_its_line(text, message, line):
    with pytest.raises(TreeFormatError) as caught:
        read_plan(text, "bad.plan")
    (file, at, problem), = caught.value.problems
    assert file == "bad.plan" and at == line and message in problem


def test_return_to_launch_goes_to_the_nearest_rally_point_and_speed_and_yaw_follow_mavlink():
    text = plan(takeoff(4), item(178, [1, 2, -1, 0, 0, 0, 0], 2), waypoint(8, 8, 4, hold=2, yaw=0),
                item(178, [1, -2, -1, 0, 0, 0, 0], 2), waypoint(9, 9, 4, yaw=90), item(20, [0] * 7, 2),
                rally=[[*latlon(10, 10), 6]])
    nodes = leaves(read_plan(text, "rtl.plan"))
    assert nodes[1][2] == {"COORDINATES": "8, 8, 4", "SPEED": "2", "YAW_ANGLE_AT_THE_END": "90"}  # north
    assert nodes[2] == ("WAIT", "item 3 hold", {"DURATION": "2"})
    assert nodes[3][2] == {"COORDINATES": "9, 9, 4", "SPEED": "5", "YAW_ANGLE_AT_THE_END": "0"}  # hoverSpeed
    assert nodes[4][2]["COORDINATES"] == "10, 10, 4" and nodes[5][0] == "LAND"


def test_a_survey_without_items_flies_its_transect_points_at_the_cameras_distance_with_photos():
    survey = json.loads(SURVEY.read_text())["mission"]["items"][6]
    survey = copy.deepcopy(survey)
    del survey["TransectStyleComplexItem"]["Items"]
    nodes = leaves(read_plan(plan(takeoff(15), survey), "s.plan"))
    kinds = [n[0] for n in nodes[1:]]
    assert kinds == ["GO_TO_POINT", "TAKE_PHOTO"] * 10
    assert nodes[1][2]["COORDINATES"] == "-10, -10, 15"


def test_convert_writes_btcpp_xml_that_we_read_back_and_behaviortree_cpp_loads_and_ticks(tmp_path):
    out = tmp_path / "survey.xml"
    result = aeroexec("convert", str(SURVEY), "--to", "xml", "-o", str(out))
    assert result.returncode == 0, result.stderr
    text = out.read_text()
    original = read_plan(SURVEY.read_text(), str(SURVEY))
    again = read_xml(text, str(out))
    assert [(n.type, n.name, n.ports) for n in again.root.walk()] == \
        [(n.type, n.name, n.ports) for n in original.root.walk()]
    assert aeroexec("verify", str(out)).returncode == 0
    # BehaviorTree.CPP (behaviortreepy) with the palette's leaves registered; behaviortreepy cannot declare ports
    # from Python, so their port attributes are handed over as _attributes, which BT.CPP passes over
    root = ElementTree.fromstring(text)
    palette = {m.get("ID") for m in root.find("TreeNodesModel")}
    assert palette == {"TAKE_OFF", "LOOK_AT_A_POINT", "GO_TO_POINT", "TAKE_PHOTO", "WAIT", "LAND"}
    for element in root.iter():
        if element.tag in palette and "ID" not in element.attrib:
            for key in [k for k in element.attrib if k != "name"]:
                element.set(f"_{key}", element.attrib.pop(key))
    ticked: list[str] = []
    factory = bt.BehaviorTreeFactory()
    for kind in palette:
        factory.register_simple_stateful_action(kind, lambda n: (ticked.append(n.name()), "RUNNING")[1],
                                                lambda n: "SUCCESS", lambda n: None)
    tree = factory.create_tree_from_text(ElementTree.tostring(root, encoding="unicode"))
    status = bt.NodeStatus.RUNNING
    for _ in range(200):
        status = tree.tick_exactly_once()
        if status != bt.NodeStatus.RUNNING:
            break
    assert status == bt.NodeStatus.SUCCESS
    assert ticked == [n.name for n in original.root.children]


def test_convert_refuses_a_plan_with_errors_and_writes_nothing(tmp_path):
    path = tmp_path / "jump.plan"
    path.write_text(plan(takeoff(), item(177, [1, 3, 0, 0, 0, 0, 0], 2)))
    result = aeroexec("convert", str(path), "-o", str(tmp_path / "jump.xml"))
    assert result.returncode == 1 and "item 2: MAV_CMD 177 (DO_JUMP)" in result.stderr
    assert "nothing written" in result.stderr and not (tmp_path / "jump.xml").exists()


def test_the_survey_plan_flies_to_completion_on_the_simulator(tmp_path):
    result = aeroexec("run", str(SURVEY), "--plain", "--output", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "survey.plan: completed" in result.stderr
    arrived = [line for line in result.stdout.splitlines() if "drone_arrived" in line]
    for x, y in ((-10, -10), (10, -10), (10, -5), (-10, -5), (-10, 0), (10, 0), (10, 5), (-10, 5), (-10, 10),
                 (10, 10)):
        assert any(f"at ({x:.1f}, {y:.1f}, 15.0)" in line for line in arrived), (x, y)
    assert len(list(tmp_path.glob("photo_*.png"))) == 12
    assert "drone_landed" in result.stdout
    assert math.isclose(len([ln for ln in result.stdout.splitlines() if "GOAL_ACHIEVED GO_TO_POINT" in ln]), 12)
    log = read_btlog(tmp_path / "mission.btlog")  # Groot2's replay of the plan's tree
    assert log.subtrees() == [("survey", "")] and len(log.nodes()) == 1 + 28
    assert [(t.uid, t.status_name) for t in log.transitions[-2:]] == [(1, "SUCCESS"), (1, "IDLE")]
    assert write_xml(read_plan(SURVEY.read_text(), str(SURVEY)), default_catalog()).count("<GO_TO_POINT") == 12


def test_verify_and_run_place_the_plan_from_the_world_given(tmp_path):
    world = (ROOT / "drones" / "sim" / "default_world.yaml").read_text()
    moved = world.replace("home: {lat: 47.397742,", "home: {lat: 47.396842,")  # 100 m further south
    assert moved != world
    (tmp_path / "south.yaml").write_text(moved)
    result = aeroexec("verify", str(SURVEY), "--world", str(tmp_path / "south.yaml"))
    assert result.returncode == 1
    assert "the plan's home is 100 m from the world's home" in result.stdout
    out_of_range = [ln for ln in result.stdout.splitlines() if "WRONG_VALUE" in ln and "COORDINATES" in ln]
    assert out_of_range and all(ln.startswith(f"{SURVEY}:") for ln in out_of_range)  # y beyond 100 m north
    breaches = [ln for ln in result.stdout.splitlines() if "outside every inclusion fence" in ln]
    assert len(breaches) == 1 and "item 1: TAKEOFF at (0, 0, 15)" in breaches[0]  # the drone starts at the
    # world's home, 100 m south of the fence, which moved north with the plan's waypoints


def test_convert_writes_yaml_trees_as_xml_and_refuses_tml(tmp_path):
    out = tmp_path / "patrol.xml"
    assert aeroexec("convert", str(ROOT / "missions" / "square_patrol.yaml"), "-o", str(out)).returncode == 0
    assert '<SubTree ID="Square" />' in out.read_text() and aeroexec("verify", str(out)).returncode == 0
    tml = aeroexec("convert", str(ROOT / "missions" / "search_for_object.tml.xml"))
    assert tml.returncode == 1 and "a TML mission does not convert" in tml.stderr and not tml.stdout
