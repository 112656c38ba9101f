"""Aerostack2's mission-interpreter missions ({target, plan: [{behavior, method, args}]}) in JSON or YAML run,
verify and convert like any tree mission."""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

import behaviortreepy as bt
import pytest
from aeroexec.cli.main import main
from aeroexec.dialects.aerostack2.plans import read_aerostack2_plan
from aeroexec.trees.model import TreeFormatError
from flying import PLANS, fly

GAZEBO = ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT", "LAND"]


@pytest.mark.parametrize("plan, achieved", [
    ("as2_test_interpreter_load_modules.json", ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]),
    ("gazebo_mission_interpreter_plan.json", GAZEBO),
    ("gazebo_mission_interpreter_plan.yaml", GAZEBO),
])
def test_interpreter_missions_fly(plan, achieved, tmp_path, capsys):
    flight = fly(PLANS / plan, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == achieved
    steps = [(r["behavior"], r["detail"]) for r in flight.kinds("activated") if r["behavior"] != "KEEP_HOVERING"
             and r.get("data", {}).get("source") == "mission"]
    assert steps[0] == ("TAKE_OFF", "ALTITUDE=2.0" if plan.startswith("as2") else "ALTITUDE=1.0")
    assert "tree plan: IDLE -> RUNNING" in flight.out and "tree plan: RUNNING -> SUCCESS" in flight.out


def text(body: str) -> str:
    return '{"target": "drone0", "plan": [\n' + body + "\n]}\n"


@pytest.mark.parametrize("body, line, message", [
    ('{"behavior": "takeof", "args": {"height": 2.0}}', 2,
     "plan item 1: The behavior module takeof does not exist in Aerostack2's Python API"),
    ('{"behavior": "go_to", "method": "go_to_pont", "args": {}}', 2,
     "plan item 1: The method go_to_pont does not exist in Aerostack2's go_to module"),
    ('{"behavior": "takeoff", "args": {"height": 2.0}},\n{"behavior": "go_to", "args": {"x": 1, "y": 2}}', 3,
     "plan item 2: go_to() needs argument z"),
    ('{"behavior": "land", "args": [0.5]}', 2, "plan item 1: args must be a mapping of argument names to values"),
    ('{"args": {}}', 2, "plan item 1 has no behavior (takeoff, go_to, follow_path, land...)"),
    ('{"behavior": "go_to", "args": {"x": 1, "y": 1, "z": 2, "speed": 1, "frame_id": "map"}}', 2,
     "plan item 1: The frame 'map' of go_to() is not correct"),
])
def test_a_wrong_plan_is_refused_at_its_item(body, line, message):
    with pytest.raises(TreeFormatError) as refused:
        read_aerostack2_plan(text(body), "plan.json")
    assert [(f, n) for f, n, _ in refused.value.problems][0] == ("plan.json", line)
    assert refused.value.problems[0][2].startswith(message)


def test_verify_judges_each_item_as_a_catalog_request_at_its_line(tmp_path, capsys):
    path = tmp_path / "plan.yaml"
    path.write_text("target: drone0\nplan:\n- behavior: go_to\n  args: {x: 1, y: 1, z: 2, speed: 0}\n"
                    "- behavior: takeoff\n  args: {height: 800}\n")
    assert main(["verify", str(path)]) == 1
    captured = capsys.readouterr()
    err = captured.out + captured.err
    assert f"{path}:3: error: WRONG_VALUE: The value 0 of argument SPEED for behavior GO_TO_POINT" in err
    assert f"{path}:5: error: WRONG_VALUE: The value 800 of argument ALTITUDE for behavior TAKE_OFF" in err
    assert f"{path}:3: error: WRONG_SEQUENCE: The execution of behavior GO_TO_POINT cannot be done" in err


def test_a_plan_converts_to_behaviortree_cpp_xml_that_behaviortree_cpp_ticks(tmp_path, capsys):
    out = tmp_path / "plan.xml"
    assert main(["convert", str(PLANS / "gazebo_mission_interpreter_plan.json"), "-o", str(out)]) == 0
    root = ElementTree.parse(out).getroot()
    leaves = [e.tag for e in root.iter() if e.tag in ("TAKE_OFF", "GO_TO_POINT", "LAND")]
    assert leaves == GAZEBO
    factory = bt.BehaviorTreeFactory()
    for name in set(leaves):
        factory.register_simple_action(name, lambda node: "SUCCESS")
    for model in root.findall("TreeNodesModel"):
        root.remove(model)
    for element in root.iter():
        if element.tag in leaves:
            element.attrib.clear()  # the ports were checked by verify; the palette is what BT.CPP needs
    ElementTree.ElementTree(root).write(tmp_path / "bare.xml")
    tree = factory.create_tree_from_file(str(tmp_path / "bare.xml"), bt.Blackboard.create())
    assert tree.tick_while_running() == bt.NodeStatus.SUCCESS
