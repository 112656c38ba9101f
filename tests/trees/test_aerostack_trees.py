"""Aerostack's own tree missions run unchanged: the Levant TML wiki's complete example (a variable consulted after
take-off, an unnamed argument, upper-case belief values), behavior_tree_interpreter files with ``&`` parameters,
and other dialects named in one line."""

from __future__ import annotations

from pathlib import Path

import pytest
from aeroexec.dialects.aerostack.nodes import split_parameters
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.flight.missions import check_mission
from aeroexec.flight.robot import chosen_catalog
from aeroexec.trees import TreeFormatError, load_mission_tree, read_mission_tree
from aeroexec.trees.runtime.runner import TreeMission
from py_trees.common import Status

DATA = Path(__file__).parent / "data" / "aerostack"
WIKI = DATA / "levant_search_for_object.tml.xml"


def fly(document, battery: float = 100.0, max_time: float = 200.0) -> tuple[Engine, TreeMission]:
    world = default_world()
    drone = SimulatedDrone(world, config=SimConfig(initial_battery_percent=battery, battery_hover_minutes=3.0))
    engine = Engine(drone, obstacles=world)
    run = TreeMission(document, engine)
    try:
        run.run(max_time)
    finally:
        engine.stop()
    return engine, run


def kinds(engine: Engine, kind: str, behavior: str = "") -> list:
    return [e for e in engine.log.events(kind=kind) if not behavior or e.behavior == behavior]


def problems(path: Path) -> list[tuple[str, int, str]]:
    return [(p.severity, p.line, p.message) for p in check_mission(path, chosen_catalog(None)).problems]


# -- TML --------------------------------------------------------------------------------------------------------
def test_the_wiki_example_verifies_with_warnings_for_the_variables_an_event_may_find_unbound():
    found = problems(WIKI)
    assert [severity for severity, _, _ in found] == ["warning", "warning"]
    assert found[0][2].startswith("+HOME_X may not be bound when the event 'Object found' fires: it can fire during "
                                  "the task 'Take off' (line 11)")


def test_the_wiki_example_finds_the_object_and_flies_home():
    engine, run = fly(load_mission_tree(WIKI))
    assert run.status == Status.SUCCESS
    fired = kinds(engine, "tml_event")
    assert len(fired) == 1 and fired[0].detail.startswith("Object found: color(?OBJ, red), visible(?OBJ) holds")
    assert kinds(engine, "activated", "TAKE_OFF")[0].data["arguments"] == {"ALTITUDE": 2}  # the unnamed argument
    assert engine.memory.holds("picked_up(object_1)")
    x, y, z = engine.drone.telemetry().position
    assert (x, y, z) == pytest.approx((0, 0, 0), abs=0.3)  # home, as consulted after take-off


def test_the_upper_case_low_battery_event_fires_and_aborts():
    engine, run = fly(load_mission_tree(WIKI), battery=21.0)
    assert run.status == Status.FAILURE
    fired = kinds(engine, "tml_event")
    assert len(fired) == 1 and fired[0].detail.startswith("Low battery: battery_level(self, LOW) holds")
    assert kinds(engine, "GOAL_ACHIEVED", "LAND")
    assert [e for e in kinds(engine, "tml_termination") if "ABORT_MISSION" in e.detail]


def test_an_event_firing_while_its_variable_is_unbound_fails_the_mission_clearly():
    text = WIKI.read_text().replace('<condition belief="color(?OBJ, red), visible(?OBJ)"/>',
                                    '<condition belief="flight_state(self, TAKING_OFF)"/>')
    text = text.replace('<task name="Locate the object">\n        <consult belief="color(?OBJ, red), '
                        'position(?OBJ,(?OBJ_X,?OBJ_Y,?))"/>',
                        '<task name="Locate the object">\n        <consult belief="position(self,(?OBJ_X,?OBJ_Y,?))"/>')
    engine, run = fly(read_mission_tree(text, "unbound.tml.xml"))
    assert run.status == Status.FAILURE
    failed = kinds(engine, "tml_handler_failed")
    assert len(failed) == 1
    assert failed[0].detail == ("Object found: +HOME_X, +HOME_Y not bound: the event fired before any <consult> "
                                "bound ?HOME_X, ?HOME_Y; the tree Retrieve object cannot run and the mission fails")
    assert not kinds(engine, "activated", "GO_TO_POINT")  # nothing of the handler's tree flew


def test_an_unnamed_argument_of_a_behavior_with_several_is_refused_by_name():
    text = WIKI.read_text().replace('<argument name="coordinates" value="[-3.0, -4.0, 2.0]"/>',
                                    '<argument value="[-3.0, -4.0, 2.0]"/>')
    with pytest.raises(TreeFormatError) as caught:
        read_mission_tree(text, "unnamed.tml.xml")
    (_, line, message), = caught.value.problems
    assert line == 24 and message.startswith("<argument> without name: the behavior GO_TO_POINT has not one "
                                             "argument (its arguments are COORDINATES, RELATIVE_COORDINATES")


def test_a_gregale_mission_is_named_in_one_line():
    found = problems(DATA / "gregale_mission.xml")
    assert len(found) == 1 and found[0][:2] == ("error", 4)
    assert "older Gregale dialect (TML v1: <macro_task>, <action>, <skill>)" in found[0][2]


# -- behavior_tree_interpreter YAML -----------------------------------------------------------------------------
def test_ampersand_parameters_are_several_arguments():
    assert split_parameters("path: [[1,2,3],[4,5,6]] & speed: 2") == "path: [[1,2,3],[4,5,6]]\nspeed: 2"
    assert split_parameters("message: 'fish & chips'") == "message: 'fish & chips'"
    document = load_mission_tree(DATA / "bt_interpreter_path.yaml")
    follow = document.root.children[1]
    assert follow.type == "FOLLOW_PATH" and follow.ports == {"PATH": "[[1, 0, 2], [2, 2, 2]]", "SPEED": "1"}
    assert problems(DATA / "bt_interpreter_path.yaml") == []


def test_a_behavior_tree_interpreter_mission_with_and_parameters_flies():
    engine, run = fly(load_mission_tree(DATA / "bt_interpreter_path.yaml"))
    assert run.status == Status.SUCCESS
    assert [e.behavior for e in kinds(engine, "GOAL_ACHIEVED")] == ["TAKE_OFF", "FOLLOW_PATH", "GO_TO_POINT",
                                                                    "LAND"]
    assert kinds(engine, "activated", "FOLLOW_PATH")[0].data["arguments"]["SPEED"] == 1
    assert engine.memory.holds("patrolled(east_sector)")
    x, y, _ = engine.drone.telemetry().position
    assert (x, y) == pytest.approx((0, 2), abs=0.3)  # back along x, at the y the query bound


def test_catalog_errors_come_with_the_readers():
    found = problems(DATA / "bt_interpreter_mistakes.yaml")
    assert found == [("error", 9, "The behavior TAKE_OF does not exist (did you mean TAKE_OFF?)"),
                     ("error", 20, "node 3: its parent 9 is not in the list")]


@pytest.mark.parametrize("name, start", [
    ("other_nodes_dialect.yaml", "this nodes: list is not in the format of Aerostack's behavior_tree_interpreter "
                                 "(its items have id, type, children, action"),
    ("other_yaml_dialect.yaml", "not a behavior-tree mission: expected tree:"),
])
def test_another_yaml_dialect_is_one_line(name, start):
    found = problems(DATA / name)
    assert len(found) == 1 and found[0][2].startswith(start)
