"""Aerostack's own behavior catalogs: Levant's keys are read, thin descriptors take the implementation's arguments,
behaviors no implementation serves are refused before flight, and other Aerostack formats are named."""

import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.dialects.aerostack import executive_engine_api as api
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.catalog import default_catalog, load_catalog, parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.errors import CatalogError
from aeroexec.engine.library import default_library
from aeroexec.engine.missions.check import check_mission_file

DATA = Path(__file__).parents[1] / "engine" / "data" / "aerostack"
LEVANT = DATA / "levant_behavior_catalog.yaml"


def served(catalog):
    return catalog.served_by(default_library().names(), default_catalog())


def aeroexec(*args, cwd):
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=cwd)


def test_a_levant_catalog_with_required_capabilities_is_read():
    catalog = load_catalog(LEVANT)
    assert catalog.behavior("GO_TO_POINT").capabilities == ("SETPOINT_BASED_FLIGHT_CONTROL", "PATH_PLANNING")
    assert catalog.warnings == []
    fitted = served(catalog)
    assert fitted.unsupported == {"DROP_OBJECT"}
    # ROTATE and LAND have no arguments: they take those of their implementation; GO_TO_POINT keeps its own
    assert "RELATIVE_ANGLE" in fitted.behavior("ROTATE").arguments
    assert set(fitted.behavior("GO_TO_POINT").arguments) == {"COORDINATES"}
    assert fitted.behavior("GO_TO_POINT").one_of == (("COORDINATES",),)
    assert "visible" in fitted.predicates and "position" in fitted.predicates


def test_verify_refuses_an_unimplemented_behavior_and_a_request_the_implementation_cannot_serve(tmp_path):
    result = aeroexec("verify", "--catalog", str(LEVANT), str(DATA / "levant_drop.py"), cwd=tmp_path)
    assert result.returncode == 1
    assert "levant_drop.py:9:5: error: WRONG_FORMAT: The behavior DROP_OBJECT is not supported by this robot " \
           "(no implementation is registered)" in result.stdout
    assert "levant_drop.py:8:5: error: WRONG_FORMAT: The behavior GO_TO_POINT needs one of the arguments " \
           "COORDINATES" in result.stdout
    assert "will not fly" in result.stdout and "ready to fly" not in result.stdout


def test_a_levant_mission_flies_on_the_levant_catalog(tmp_path):
    result = aeroexec("verify", "--catalog", str(LEVANT), str(DATA / "levant_patrol.py"), cwd=tmp_path)
    assert result.returncode == 0 and "ready to fly" in result.stdout, result.stdout
    result = aeroexec("run", "--catalog", str(LEVANT), str(DATA / "levant_patrol.py"), "--plain", cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "GOAL_ACHIEVED ROTATE" in result.stdout and "levant_patrol.py: completed" in result.stderr


def test_a_thin_catalog_never_crashes_in_flight():
    thin = parse_catalog("""
behavior_descriptors:
  - {behavior: TAKE_OFF, required_capabilities: [SETPOINT_BASED_FLIGHT_CONTROL]}
  - {behavior: GO_TO_POINT, required_capabilities: [SETPOINT_BASED_FLIGHT_CONTROL]}
capability_descriptors:
  - {capability: SETPOINT_BASED_FLIGHT_CONTROL, process_sequence: [flight_controller]}
""")
    results = []

    def mission():
        results.append(api.executeBehavior("TAKE_OFF"))
        results.append(api.executeBehavior("GO_TO_POINT"))  # no point: refused, not a KeyError in the air
        results.append(api.executeBehavior("GO_TO_POINT", coordinates=[2, 0, 2]))

    world = default_world()
    engine = Engine(SimulatedDrone(world), catalog=thin, obstacles=world)
    try:
        engine.run(mission, max_time=120)
    finally:
        engine.stop()
    assert results == ["GOAL_ACHIEVED", "ERROR", "GOAL_ACHIEVED"]
    assert not [e for e in engine.log.events() if "KeyError" in (e.detail or "")]


@pytest.mark.parametrize("name, text", [
    ("Sirocco", (DATA / "sirocco_behavior_catalog.yaml").read_text()),
    ("Auster/Libeccio", "behaviors:\n  - {behavior: take_off, package: basic_behaviors, task: TAKE_OFF}\n"
                        "tasks:\n  - {task: TAKE_OFF, timeout: 20}\n"),
])
def test_other_aerostack_catalog_formats_are_named_in_one_line(name, text):
    with pytest.raises(CatalogError) as caught:
        parse_catalog(text, "behavior_catalog.yaml")
    assert len(caught.value.problems) == 1
    assert f"This is an Aerostack {name} behavior catalog" in str(caught.value.problems[0])


def test_the_aerostack_mission_passes_its_own_catalog_check():
    problems = check_mission_file(DATA / "levant_patrol.py", served(load_catalog(LEVANT)))
    assert problems == []


def test_catalog_check_warns_of_a_behavior_without_implementation(tmp_path):
    result = aeroexec("catalog", "--check", str(LEVANT), cwd=tmp_path)
    assert result.returncode == 0
    assert ("levant_behavior_catalog.yaml:43: warning: the behavior DROP_OBJECT has no implementation in the "
            "behavior library: missions using it are refused") in result.stdout


def test_a_tree_mission_using_an_unimplemented_behavior_is_refused_naming_it(tmp_path):
    mission = tmp_path / "drop.yaml"
    mission.write_text("nodes:\n"
                       "  - {node: 1, name: Mission, type: control_flow, subtype: sequence, parent: 0}\n"
                       "  - {node: 2, name: Take off, type: execution, subtype: task, task: TAKE_OFF, parent: 1}\n"
                       "  - {node: 3, name: Drop, type: execution, subtype: task, task: DROP_OBJECT, parent: 1}\n")
    result = aeroexec("verify", "--catalog", str(LEVANT), str(mission), cwd=tmp_path)
    assert result.returncode == 1
    assert "drop.yaml:4: error: WRONG_FORMAT: The behavior DROP_OBJECT is not supported by this robot" in result.stdout


def test_early_levant_spellings_are_read():
    catalog = parse_catalog("""
behavior_descriptors:
  - {behavior: TAKE_OFF, incompatibilities: motion, capabilities: SETPOINT_BASED_FLIGHT_CONTROL}
  - {behavior: LAND, incompatibilities: [motion], capabilities: [SETPOINT_BASED_FLIGHT_CONTROL]}
behavior_lists:
  - name: motion
    behaviors: [TAKE_OFF, LAND]
capability_descriptors:
  - {capability: SETPOINT_BASED_FLIGHT_CONTROL, process_sequence: [flight_controller]}
""")
    assert catalog.incompatible("TAKE_OFF", "LAND") and catalog.warnings == []
    assert catalog.behavior("TAKE_OFF").capabilities == ("SETPOINT_BASED_FLIGHT_CONTROL",)
