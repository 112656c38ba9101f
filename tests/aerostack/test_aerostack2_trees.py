"""Aerostack2's behavior trees (BehaviorTree.CPP 3 XML with as2_behavior_tree's nodes) run where their nodes have a
meaning here: each node is a catalog behavior, a belief check or an event; nodes bound to ROS 2 topics are refused
by name. The trees are Aerostack2's own (tests/aerostack/data/SOURCES.md)."""

from __future__ import annotations

import re

import pytest
from aeroexec.dialects.aerostack2.tree_nodes import PORTS
from aeroexec.drones.sim import SimulatedDrone, load_world
from aeroexec.engine.engine import Engine
from aeroexec.trees.mission_file import load_mission_tree
from aeroexec.trees.model import TreeFormatError
from aeroexec.trees.runtime.runner import TreeMission
from aeroexec.trees.verify import verify_document
from flying import DATA, EMPTY_WORLD, TREES, fly, world
from py_trees.common import Status


def run_tree(path, world_file=EMPTY_WORLD, events=(), max_time=120.0):
    """Fly a tree on the simulated drone; ``events`` are ``(engine seconds, belief)`` the operator adds."""
    place = load_world(world_file)
    engine = Engine(SimulatedDrone(place), obstacles=place)
    document = load_mission_tree(path, place.home)
    assert not [p for p in verify_document(document, engine.catalog, world=place) if p.severity == "error"]
    for seconds, belief in events:
        engine.timers.after(seconds, lambda b=belief: engine.supervisor.execute("add", b, origin="ctl"))
    mission = TreeMission(document, engine, name=path.name)
    try:
        status = mission.run(max_time=max_time)
    finally:
        engine.stop()
    return status, engine


def achieved(engine) -> list[str]:
    return [e.behavior for e in engine.log.events(kind="GOAL_ACHIEVED") if e.behavior != "KEEP_HOVERING"]


def test_every_node_aerostack2_registers_has_a_meaning_or_a_refusal_here():
    source = (DATA / "as2_behavior_tree_node.cpp").read_text()
    registered = set(re.findall(r'registerNodeType<[\w:]+>\("(\w+)"\)', source))
    assert registered and registered <= set(PORTS)


def test_the_basic_mission_flies():
    status, engine = run_tree(TREES / "as2_basic_mission.xml")
    assert status is Status.SUCCESS
    assert achieved(engine) == ["TAKE_OFF", "GO_TO_POINT", "LAND"]
    go_to = engine.log.events(kind="activated", behavior="GO_TO_POINT")[0].detail
    assert "COORDINATES=(5, 5, 2)" in go_to and "SPEED=2" in go_to  # pose="5;5;2" max_speed="2"


def test_a_project_tree_waits_for_its_start_event_from_the_operator():
    status, engine = run_tree(TREES / "gazebo_square.xml", events=[(5.0, "event(start, go)")])
    assert status is Status.SUCCESS
    assert achieved(engine) == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    assert engine.log.events(kind="activated", behavior="TAKE_OFF")[0].time >= 5.0  # not before the operator said
    unsent, engine = run_tree(TREES / "gazebo_square.xml", max_time=20.0)
    assert unsent is not Status.SUCCESS and not engine.log.events(kind="activated", behavior="TAKE_OFF")


def test_events_sent_and_waited_for_echo_their_data_in_order():
    status, engine = run_tree(TREES / "as2_event_test_2.xml")
    assert status is Status.SUCCESS
    echoed = [e.detail for e in engine.log.events(kind="operator") if e.data.get("action") == "notify"]
    assert echoed == ["1", "2", "3", "4"]


def test_the_takeoff_tree_runs_its_subtree_with_the_ports_it_gives():
    status, engine = run_tree(TREES / "as2_takeoff.xml", events=[(1.0, "event('mission/start', '')")])
    assert status is Status.SUCCESS
    assert engine.log.events(kind="activated", behavior="TAKE_OFF")[0].detail == "ALTITUDE=2"
    assert engine.drone.telemetry().altitude == pytest.approx(2.0, abs=0.3)  # IsFlying now holds: it stays up


def test_an_rtl_tree_flies_to_gps_points_placed_from_its_origin(tmp_path):
    here = world(tmp_path, 52.171776, 4.416351)  # RTL_test_2's SetOrigin
    status, engine = run_tree(TREES / "as2_RTL_test_2.xml", world_file=here)
    assert status is Status.SUCCESS
    assert achieved(engine) == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    out, back = [e.detail for e in engine.log.events(kind="activated", behavior="GO_TO_POINT")]
    assert "COORDINATES=(30.034, 30.043, 2.0)" in out and "COORDINATES=(0, 0, 2.0)" in back, (out, back)


def test_an_origin_that_is_not_the_home_point_is_refused():
    with pytest.raises(TreeFormatError) as refused:
        load_mission_tree(TREES / "as2_RTL_test_2.xml", load_world(EMPTY_WORLD).home)
    assert any(line == 6 and "SetOrigin (52.171776, 4.416351) is" in message and "the earth frame is fixed at home"
               in message for _, line, message in refused.value.problems)


def test_a_later_rtl_is_called_by_its_event():
    status, engine = run_tree(TREES / "mbzirc_takeoff_only_test.xml", events=[(30.0, "event('mission/rtl', now)")])
    assert status is Status.SUCCESS
    assert achieved(engine) == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "LAND"]
    assert engine.log.events(kind="activated", behavior="TAKE_OFF")[0].time == pytest.approx(5.0)  # Delay 5000 ms


@pytest.mark.parametrize("tree, line, message", [
    ("as2_follow_path_test.xml", 16, "FollowPath takes its path from the ROS 2 topic 'test' (this mission uses ROS 2 "
                                     "beyond the drone interface)"),
    ("mbzirc_inspection.xml", 31, "The node IsTargetDetected is bound to the ROS 2 topic 'vessel/identification' "
                                  "(this mission uses ROS 2 beyond the drone interface)"),
])
def test_nodes_bound_to_ros_2_topics_are_refused_by_name(tree, line, message, tmp_path, capsys):
    flight = fly(TREES / tree, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert f"{tree}:{line}: error: {message}" in flight.err


@pytest.mark.parametrize("tree", ["as2_arm_test.xml", "as2_test.xml", "gazebo_go.xml"])
def test_aeroexec_run_takes_aerostack2_trees(tree, tmp_path, capsys):
    flight = fly(TREES / tree, tmp_path, capsys, "--max-time", "60")
    if tree == "gazebo_go.xml":  # it waits for its start event, which nobody sends here: the time limit ends it
        detail = flight.kinds("mission_failed")[0]["detail"]
        assert flight.status == 1 and "time limit" in detail
        assert "it was waiting for the belief event('start', ?) (" in detail and "gazebo_go.xml:6)" in detail, detail
        assert not [r for r in flight.kinds("activated") if r["behavior"] == "TAKE_OFF"]
    else:
        assert flight.status == 0, flight.err


def test_strict_btcpp_says_an_aerostack2_file_is_not_behaviortree_cpp_4(tmp_path, capsys):
    from aeroexec.cli.main import main

    assert main(["verify", "--strict-btcpp", "--no-world", str(TREES / "as2_basic_mission.xml")]) == 1
    assert "NOT_PORTABLE: written for BehaviorTree.CPP 3 with Aerostack2's nodes" in capsys.readouterr().out


@pytest.mark.parametrize("tree", ["as2_basic_mission.xml", "as2_takeoff.xml", "as2_test.xml", "gazebo_square.xml",
                                  "gazebo_go_back.xml"])
def test_what_aeroexec_makes_of_aerostack2_trees_is_behaviortree_cpp_4_that_it_ticks(tree, tmp_path, capsys):
    import xml.etree.ElementTree as ElementTree

    import behaviortreepy as bt
    from aeroexec.cli.main import main

    out = tmp_path / "v4.xml"
    assert main(["convert", str(TREES / tree), "-o", str(out), "--world", str(EMPTY_WORLD)]) == 0
    root = ElementTree.parse(out).getroot()
    for model in root.findall("TreeNodesModel"):
        root.remove(model)
    factory = bt.BehaviorTreeFactory()
    conditions = {"CheckBelief", "QueryBelief"}
    leaves = {e.tag for e in root.iter() if e.tag.isupper() or e.tag in conditions | {"AddBelief"}}
    for name in leaves:
        register = factory.register_simple_condition if name in conditions else factory.register_simple_action
        register(name, lambda node: "SUCCESS")
    for element in root.iter():
        if element.tag in leaves:  # their ports were checked by verify; BT.CPP needs the palette's names only
            element.attrib = {k: v for k, v in element.attrib.items() if k == "name"}
    ElementTree.ElementTree(root).write(tmp_path / "bare.xml")
    ticked = factory.create_tree_from_file(str(tmp_path / "bare.xml"), bt.Blackboard.create())
    assert ticked.tick_while_running() == bt.NodeStatus.SUCCESS


def test_a_palette_of_node_models_is_refused_saying_it_holds_no_tree(tmp_path, capsys):
    """behaviour_trees' resource/actions.xml: Aerostack2's node models for Groot, no BehaviorTree to run."""
    palette = tmp_path / "actions.xml"
    palette.write_text('<root>\n  <TreeNodesModel>\n    <Action ID="Arm"/>\n  </TreeNodesModel>\n</root>\n')
    flight = fly(palette, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert f"{palette}:1: error: the file declares no <BehaviorTree>: it holds only a <TreeNodesModel>, the models " \
           f"of nodes (a palette for Groot and the trees that use them), no tree to run" in flight.err
