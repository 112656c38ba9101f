"""Aerostack's own Python missions run unchanged: Levant's ``executive_engine_api`` and Sirocco's
``mission_execution_control``, their return conventions, new predicates, polling on the simulated clock."""

import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.dialects.aerostack import executive_engine_api, mission_execution_control
from aeroexec.drones.sim import SimConfig, SimulatedDrone, default_world
from aeroexec.engine.engine import Engine
from aeroexec.engine.missions.bridge import POLLING_REPORT
from aeroexec.engine.missions.check import check_mission_file, check_mission_source
from aeroexec.flight.missions import mission_function

DATA = Path(__file__).parent / "data" / "aerostack"


def load(name: str):
    """The mission's function, loaded as aeroexec loads a mission (its imports of Aerostack's APIs mapped)."""
    return mission_function(DATA / f"{name}.py")


def run(mission, max_time=300.0, battery=100.0):
    world = default_world()
    engine = Engine(SimulatedDrone(world, config=SimConfig(initial_battery_percent=battery)), obstacles=world)
    try:
        engine.run(mission, max_time=max_time)
    finally:
        engine.stop()
    return engine


def kinds(engine, kind, behavior=None):
    return engine.log.events(kind=kind, behavior=behavior) if behavior else engine.log.events(kind=kind)


def test_the_levant_search_mission_polls_until_the_object_is_seen_then_goes_home():
    engine = run(load("levant_search_for_object"))
    assert kinds(engine, "mission_completed") and not kinds(engine, "mission_failed")
    # the polling loop let simulated time move: GO_TO_POINT flew until the barrel was in view, then was stopped
    # through the uid activateBehavior returned
    stopped = kinds(engine, "INTERRUPTED", "GO_TO_POINT")[0]
    assert stopped.detail == "inhibited by the mission" and stopped.time > 2.0
    assert not any(e.detail.startswith("at (-2.0, -8.0") for e in kinds(engine, "drone_arrived"))
    assert kinds(engine, "INTERRUPTED", "PAY_ATTENTION_TO_COLORS")[0].time == stopped.time
    # the new predicates the mission added, and the one it removed
    assert engine.memory.holds("picked_up(yellow_barrel)")
    assert not engine.memory.holds("found_at(?, ?)")
    assert kinds(engine, "GOAL_ACHIEVED", "LAND")
    assert engine.drone.telemetry().altitude == pytest.approx(0.0, abs=0.05)


def test_the_sirocco_patrol_runs_its_tasks():
    engine = run(load("sirocco_patrol"))
    assert kinds(engine, "mission_completed")
    assert [e.behavior for e in kinds(engine, "GOAL_ACHIEVED")] == ["TAKE_OFF", "FOLLOW_PATH", "ROTATE", "LAND"]
    assert kinds(engine, "INTERRUPTED", "PAY_ATTENTION_TO_VISUAL_MARKERS")[0].detail == "inhibited by the mission"
    assert engine.memory.holds("patrolled(sector_1, 4)")


def test_levant_return_conventions():
    api = executive_engine_api
    seen = {}

    def runMission():
        seen["refused"] = api.executeBehavior("LAND")  # landed already: its preconditions fail
        seen["take_off"] = api.executeBehavior("TAKE_OFF")
        seen["activate"] = api.activateBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
        seen["active"] = api.isActiveBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
        ack, uid = seen["activate"]
        seen["unknown_uid"] = api.inhibitBehavior(uid + 1000)
        seen["by_uid"] = api.deactivateBehavior(uid, "PAY_ATTENTION_TO_VISUAL_MARKERS")
        seen["again"] = api.inhibitBehavior(uid)  # no longer active
        seen["unknown_name"] = api.inhibitBehavior("NO_SUCH_BEHAVIOR")
        seen["by_name_inactive"] = api.inhibitBehavior("PAY_ATTENTION_TO_COLORS")
        seen["add"] = api.addBelief("my_belief(a, 1)")
        seen["assert"] = api.assertBelief("tagged(marker_1)", True)
        seen["assert2"] = api.assertBelief("tagged(marker_2)", True)
        seen["query"] = api.queryBelief("my_belief(?W, ?N)")
        seen["consult"] = api.consultBelief("position(self, (?X, ?Y, ?))")
        seen["true"] = api.trueBelief("tagged(marker_1), tagged(marker_2)")
        seen["never_added"] = api.trueBelief("never_added(x)")
        seen["retract"] = api.retractBelief("my_belief(?, ?)")
        seen["retract_none"] = api.removeBelief("my_belief(?, ?)")
        seen["bad_belief"] = api.addBelief("not a belief(")
        seen["planner"] = api.consultPlanner("GENERATE_PATH_FREE_OF_OBSTACLES", destination=[2, 0, 2])
        seen["land"] = api.executeBehavior("LAND")

    engine = run(runMission)
    assert kinds(engine, "mission_completed")
    assert seen["refused"] == "ERROR" and seen["take_off"] == "GOAL_ACHIEVED"
    ack, uid = seen["activate"]
    assert ack is True and isinstance(uid, int) and uid > 0 and seen["active"] is True
    assert seen["unknown_uid"] is False and seen["by_uid"] is True and seen["again"] is False
    assert seen["unknown_name"] is False and seen["by_name_inactive"] is False
    assert seen["add"] is True and seen["assert"] is True
    assert seen["query"] == (True, {"W": "a", "N": 1})
    success, position = seen["consult"]
    assert success and set(position) == {"X", "Y"} and position["X"] == pytest.approx(0.0, abs=0.2)
    assert seen["true"] is True and seen["never_added"] is False
    assert seen["retract"] is True and seen["retract_none"] is False and seen["bad_belief"] is False
    assert seen["planner"] and seen["planner"][-1] == pytest.approx((2, 0, 2), abs=0.01)
    assert seen["land"] == "GOAL_ACHIEVED"


def test_sirocco_return_conventions():
    mxc = mission_execution_control
    seen = {}

    def mission():
        seen["refused"] = mxc.executeTask("LAND")
        seen["take_off"] = mxc.executeTask("TAKE_OFF")
        seen["start"] = mxc.startTask("PAY_ATTENTION_TO_VISUAL_MARKERS")
        seen["stop"] = mxc.stopTask("PAY_ATTENTION_TO_VISUAL_MARKERS")
        seen["stop_again"] = mxc.stopTask("PAY_ATTENTION_TO_VISUAL_MARKERS")
        seen["bad_start"] = mxc.startTask("TAKE_OFF")  # flying: TAKE_OFF's goal is reached, nothing starts
        seen["land"] = mxc.executeTask("LAND")

    engine = run(mission)
    assert kinds(engine, "mission_completed")
    assert seen["refused"] == (False, "ERROR") and seen["take_off"] == (True, "GOAL_ACHIEVED")
    assert seen["start"] is True and seen["stop"] is True and seen["stop_again"] is False
    assert seen["bad_start"] is False and seen["land"] == (True, "GOAL_ACHIEVED")


def test_a_mission_polling_a_world_that_does_not_change_is_reported_and_the_time_limit_ends_it():
    engine = run(load("levant_waits_for_nothing"), max_time=POLLING_REPORT + 10)
    assert kinds(engine, "engine_time_limit")  # simulated time moved although the mission never waited
    reported = kinds(engine, "mission_polling")
    assert len(reported) == 1 and reported[0].time == pytest.approx(POLLING_REPORT, abs=0.1)
    assert "no belief has changed" in reported[0].detail
    assert not kinds(engine, "mission_completed")


def test_polling_while_the_world_changes_is_not_reported():
    api = executive_engine_api

    def mission():
        api.executeBehavior("TAKE_OFF")
        api.activateBehavior("GO_TO_POINT", coordinates=[-15, 0, 2], speed=0.4)  # a slow flight: 35 s
        while not api.trueBelief("position(self, (?X, ?, ?)), less_than(?X, -14)"):
            pass
        api.executeBehavior("LAND")

    engine = run(mission)
    assert kinds(engine, "mission_completed") and not kinds(engine, "mission_polling")
    assert engine.now() > POLLING_REPORT


def problems(source: str):
    return [(p.line, p.severity, p.message) for p in check_mission_source(source, "m.py")]


def test_verify_accepts_the_aerostack_missions():
    for name in ("levant_search_for_object", "sirocco_patrol", "levant_waits_for_nothing"):
        assert [p for p in check_mission_file(DATA / f"{name}.py") if p.severity == "error"] == [], name


@pytest.mark.parametrize("imports, prefix", [
    ("import executive_engine_api as api", "api."),
    ("import executive_engine_api", "executive_engine_api."),
    ("from executive_engine_api import *", ""),
    ("from executive_engine_api import executeBehavior, activateBehavior, inhibitBehavior, addBelief, trueBelief",
     ""),
])
def test_verify_knows_every_import_form_of_the_levant_module(imports, prefix):
    found = problems(f"""{imports}

def runMission():
    {prefix}executeBehavior('TAKE_OF')
    ack, uid = {prefix}activateBehavior('PAY_ATTENTION_TO_VISUAL_MARKERS')
    {prefix}inhibitBehavior(uid)
    {prefix}addBelief('my_belief(a, 1)')
    {prefix}trueBelief('my_belief(?, ?)')
    {prefix}trueBelief('nobody_writes(?)')
""")
    assert [(line, severity) for line, severity, _ in found] == [(4, "error"), (9, "error")]
    assert "The behavior TAKE_OF does not exist (did you mean TAKE_OFF?)" in found[0][2]
    assert "The predicate nobody_writes" in found[1][2]


def test_verify_knows_the_sirocco_module_and_its_spellings():
    found = problems("""import mission_execution_control as mxc

def mission():
    mxc.executeTask('TAKE_OFF')
    mxc.startTask('FOLLOW_PATH', path=[[0, 0, 2], [1, 0, 2]], speed=99)
    mxc.executeBehavior('LAND')
    mxc.stopTask('LANDD')
""")
    assert [(line, severity) for line, severity, _ in found] == [(5, "error"), (6, "error"), (7, "error")]
    assert "speed" in found[0][2].lower()
    assert found[1][2].startswith("The function executeBehavior does not exist in the mission API "
                                  "mission_execution_control")
    assert "The behavior LANDD does not exist" in found[2][2]


def test_verify_warns_of_a_value_no_updater_writes_but_takes_aerostack_spellings():
    found = problems("""import executive_engine_api as api

def runMission():
    api.trueBelief('battery_level(self, LOW)')
    api.trueBelief('flight_state(self, LANDED)')
    api.trueBelief('battery_level(self, critical)')
    api.trueBelief('flight_state(self, FLYING)')
""")
    assert len(found) == 1 and found[0][:2] == (6, "warning")
    assert found[0][2] == ("The belief battery_level(self, critical) can never hold: battery_level is written with "
                           "low, medium, high, never critical")


def test_a_computed_belief_turns_unknown_predicates_into_warnings():
    found = problems("""import executive_engine_api as api

def runMission():
    name = 'seen'
    api.addBelief(name + '(x)')
    api.trueBelief('seen(x)')
""")
    assert [(line, severity) for line, severity, _ in found] == [(6, "warning")]


def test_upper_case_values_and_aliases_match_what_the_updater_writes():
    api = executive_engine_api
    seen = {}

    def mission():
        seen["landed"] = api.trueBelief("flight_state(self, LANDED)")
        seen["high"] = api.trueBelief("battery_level(self, HIGH)")
        seen["low"] = api.trueBelief("battery_level(self, LOW)")
        seen["flying before"] = api.trueBelief("flight_state(self, FLYING)")
        api.executeBehavior("TAKE_OFF")
        seen["flying"] = api.queryBelief("flight_state(self, FLYING), flight_state(self, ?S)")
        seen["not flying"] = api.trueBelief("not(flight_state(self, FLYING))")
        api.executeBehavior("LAND")

    run(mission)
    assert seen == {"landed": True, "high": True, "low": False, "flying before": False,
                    "flying": (True, {"S": "hovering"}), "not flying": False}


def test_a_python_2_mission_gets_one_line():
    found = problems("import executive_engine_api as api\n\ndef runMission():\n    print 'Starting'\n")
    assert len(found) == 1 and found[0][0] == 4 and "not valid Python" in found[0][2]
    assert "print" in found[0][2]
    mixed = problems("import executive_engine_api as api\n\ndef runMission():\n    api.executeBehavior('TAKE_OFF')\n"
                     "\tapi.executeBehavior('LAND')\n")
    assert len(mixed) == 1 and mixed[0][0] == 5 and "tabs" in mixed[0][2]


def test_aeroexec_verify_and_run_take_a_levant_mission_as_it_is(tmp_path):
    mission = DATA / "levant_search_for_object.py"
    verify = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "verify", str(mission)],
                            capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert verify.returncode == 0, verify.stdout + verify.stderr
    result = subprocess.run([sys.executable, "-m", "aeroexec.cli.main", "run", str(mission), "--quiet"],
                            capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "completed" in result.stderr + result.stdout and "Finish mission..." in result.stdout


def test_a_module_that_cannot_be_found_is_an_error_not_ready_to_fly():
    found = problems("""import sirocco_helpers
import executive_engine_api as api
try:
    import optional_helper
except ImportError:
    optional_helper = None

def runMission():
    api.executeBehavior('TAKE_OFF')
""")
    assert found == [(1, "error", "The module sirocco_helpers cannot be found: the mission would stop at this "
                                  "import")]


def test_a_ros_module_imported_and_never_used_is_a_warning_and_its_use_an_error_at_its_line():
    unused = problems("""import rospy
import mission_execution_control as mxc

def mission():
    mxc.executeTask('TAKE_OFF')
    mxc.executeTask('LAND')
""")
    assert unused == [(1, "warning", "rospy is imported but never used: the mission runs without it (a use would "
                                     "be refused: this mission uses ROS beyond Aerostack's mission API)")]
    used = problems("""import rospy
from std_msgs.msg import String
import mission_execution_control as mxc

def mission():
    mxc.executeTask('TAKE_OFF')
    rospy.sleep(2)
    mxc.executeTask('LAND')
""")
    assert used == [
        (2, "warning", "std_msgs.msg.String is imported but never used: the mission runs without it (a use would "
                       "be refused: this mission uses ROS beyond Aerostack's mission API)"),
        (7, "error", "rospy.sleep: this mission uses ROS beyond Aerostack's mission API"),
    ]


def test_verify_knows_every_function_the_aerostack_modules_offer():
    from aeroexec.dialects.aerostack.api_modules import API_MODULES

    for module in (executive_engine_api, mission_execution_control):
        functions = {name for name in module.__all__ if callable(getattr(module, name))}
        name = module.__name__.rpartition(".")[2]  # as missions import it
        assert functions == set(API_MODULES[name]), name
