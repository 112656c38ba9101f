"""Aerostack2's own Python missions (tests/aerostack/data/SOURCES.md) run unchanged with ``aeroexec run``, or are
refused before flight with the reason; single-drone runs of multi-drone scripts say they need a fleet."""

from __future__ import annotations

import pytest
from flying import SCRIPTS, fly, world

T, G, F, L = "TAKE_OFF", "GO_TO_POINT", "FOLLOW_PATH", "LAND"

#: Each script that flies, and the behaviors that achieve their goal, in the order the script asks for them.
FLIES = {
    "as2_example1.py": [T, G, G, F, L],
    "as2_motion_reference.py": [T, G, L],  # hover, position, speed references; then the landing
    "crazyflie_mission.py": [T, G, G, G, G, L],
    "gazebo_mission.py": [T, *[G] * 8, L],
    "multirotor_mission.py": [T, *[G] * 8, L],
    "gazebo_mission_interpreter.py": [T, G, G, G, G, L],  # MissionInterpreter, start_mission(0), polling
    "multirotor_mission_interpreter.py": [T, G, G, G, G, L],  # start_mission(0, 0), exec_thread.join()
    "px4_vision_mission_interpreter.py": [T, G, G, G, G, L],  # MissionInterpreter(mission=...).perform_mission()
    "minimal_sensing_mission.py": [T, G, G, G, G, G, L],
    "rosconches24_example2.py": [T, G, G, G, G, L],
    "f450_mission.py": [T, F, F, F, *[G] * 15, L],  # drone.goto of Aerostack2 before 1.0
}


@pytest.mark.parametrize("script", list(FLIES))
def test_aerostack2_scripts_fly_unchanged(script, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("AEROSTACK2_SIMULATION_DRONE_ID", "drone0")  # as Aerostack2's simulation launch sets it
    flight = fly(SCRIPTS / script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == FLIES[script]
    assert not flight.kinds("failed_preconditions") and not flight.kinds("rejected")
    assert flight.kinds("run_ended")[-1]["detail"] == "completed"


def test_the_example_prints_what_aerostack2_prints_and_lands(tmp_path, capsys):
    flight = fly(SCRIPTS / "as2_example1.py", tmp_path, capsys)
    assert flight.out.index("Takeoff completed") < flight.out.index("Path finished") < flight.out.index("Bye!")
    path = [r for r in flight.kinds("activated") if r["behavior"] == F][0]["detail"]
    assert "PATH=((5, 0, 3), (5, 5, 3), (0, 5, 3), (0, 0, 3)), SPEED=5" in path
    states = [r for r in flight.records if r["kind"] == "state"]
    assert states[-1]["landed_state"] == "on_ground" and not states[-1]["armed"]
    # time.sleep(1) between the take-off and the first go_to waited on the simulated clock
    take_off = flight.kinds("GOAL_ACHIEVED")[0]["time"]
    first_go_to = [r for r in flight.kinds("activated") if r["behavior"] == G][0]["time"]
    assert first_go_to - take_off == pytest.approx(1.0, abs=0.11)


def test_gps_missions_fly_from_the_worlds_home_as_their_origin(tmp_path, capsys):
    gazebo = fly(SCRIPTS / "gazebo_mission_gps.py", tmp_path, capsys)  # the empty world at project_gazebo's origin
    assert gazebo.status == 0, gazebo.err
    assert gazebo.achieved() == [T, *[G] * 12, L]
    f450 = fly(SCRIPTS / "f450_mission_gps_2.py", tmp_path, capsys, world_file=world(tmp_path, 40.158194, -3.380795))
    assert f450.status == 0, f450.err  # gps.set_origin(its origin) is the home point: accepted
    assert f450.achieved() == [T, G, G, L]
    goal = [r for r in f450.kinds("activated") if r["behavior"] == G][0]["detail"]
    assert "COORDINATES=(-8.349, -1.221, 2.0)" in goal  # 40.158183, -3.380893 from the origin, 2 m up


def test_the_same_gps_mission_elsewhere_is_refused_before_flight(tmp_path, capsys):
    flight = fly(SCRIPTS / "f450_mission_gps_2.py", tmp_path, capsys)  # the origin is 60 km from this world's home
    assert flight.status == 1 and not flight.records
    assert "f450_mission_gps_2.py:30:9: error: WRONG_VALUE: The value (26320.436, -31306.115, 2.0) of argument " \
           "COORDINATES for behavior GO_TO_POINT is not correct" in flight.err


def test_a_script_that_only_starts_a_behavior_tree_is_refused_naming_what_flies_the_drone(tmp_path, capsys):
    """project_gazebo's mission_behavior_tree.py is a node that publishes ``start`` for the behavior tree
    as2_behavior_tree runs (WaitForEvent): its node and QoS profile are served, and run alone it would fly nothing
    (under python3 too). It is refused before flight saying so, and what to run instead."""
    flight = fly(SCRIPTS / "gazebo_mission_behavior_tree.py", tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "gazebo_mission_behavior_tree.py:56:26: error: WRONG_FORMAT: Nothing in this script flies a drone: it " \
           "uses no drone interface of Aerostack2's Python API" in flight.err
    assert "It publishes 'start' (line 56) for another program: the one that flies the drone (a behavior tree " \
           "waiting for it with WaitForEvent flies with aeroexec run TREE.xml --event start=VALUE)" in flight.err


@pytest.mark.parametrize("script, line, use", [
    ("minimal_sensing_explore.py", 34, "DroneInterface.create_subscription"),  # class Explorer(DroneInterface)
])
def test_scripts_using_ros_2_beyond_the_drone_interface_are_refused_at_the_line(script, line, use, tmp_path,
                                                                                 capsys):
    flight = fly(SCRIPTS / script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert f"{script}:{line}:" in flight.err and f"{use}: this mission uses ROS 2 beyond the drone interface" in \
        flight.err


BEFORE_1_0 = """import rclpy
from time import sleep
from python_interface.drone_interface import DroneInterface
from python_interface.modules.goto_module import GotoModule

rclpy.init()
drone = DroneInterface("drone_sim_0", verbose=True)
assert isinstance(drone.goto, GotoModule)
drone.offboard()
drone.arm()
drone.takeoff(3, 2)
sleep(1)
drone.goto(0, 5, 3, speed=1.0)
drone.follow_path([[5, 0, 3], [0, 0, 3]], 5)
drone.land(0.2)
drone.shutdown()
"""


def test_a_script_of_python_interface_before_1_0_flies(tmp_path, capsys):
    """python_interface, Aerostack2 before 1.0 (the package was renamed as2_python_api in December 2022; its
    examples/example1.py): the same drone interface under that version's module names; it was refused as ROS 2 beyond
    the drone interface."""
    script = tmp_path / "example_before_1_0.py"
    script.write_text(BEFORE_1_0)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, F, L]
    goal = [r["detail"] for r in flight.kinds("activated") if r["behavior"] == G][0]
    assert "COORDINATES=(0, 5, 3)" in goal


def test_a_script_of_python_interface_before_1_0_is_checked_as_aerostack2_scripts_are(tmp_path, capsys):
    script = tmp_path / "fp_before_1_0.py"
    script.write_text(BEFORE_1_0.replace("drone.takeoff(3, 2)", "pass"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "fp_before_1_0.py:13:1: error: WRONG_SEQUENCE: The execution of behavior GO_TO_POINT cannot be done at " \
           "the start of the mission" in flight.err


def test_a_follow_path_from_the_ground_is_refused_as_the_catalog_orders_flight(tmp_path, capsys):
    flight = fly(SCRIPTS / "as2_ex_fp.py", tmp_path, capsys)  # offboard, arm, then follow_path to climb
    assert flight.status == 1 and not flight.records
    assert "as2_ex_fp.py:43:1: error: WRONG_SEQUENCE: The execution of behavior FOLLOW_PATH cannot be done at the " \
           "start of the mission (flight is landed; FOLLOW_PATH needs hovering or moving)" in flight.err


#: A script of ours written as python_interface's own examples/ex_fp.py is (before the package's rename in December
#: 2022): offboard, arm, a follow_path from the ground as its take-off, a path flown, then the landing.
PYTHON_INTERFACE_TAKE_OFF_BY_PATH = """import rclpy
from python_interface.drone_interface import DroneInterface

rclpy.init()
uav = DroneInterface("drone0", verbose=False)
uav.offboard()
uav.arm()
uav.follow_path([[0, 0, 2.5]], 1)
uav.follow_path([[4, 0, 2.5], [4, 4, 2.5], [0, 0, 2.5]], 2)
uav.land(0.3)
uav.shutdown()
"""


def test_a_python_interface_follow_path_from_the_ground_takes_off_by_its_path(tmp_path, capsys):
    """Aerostack2 before 96d3a3f3 (2022-12-14) took a follow_path from the ground: the script of that era (it imports
    python_interface) takes off to the path's first altitude, then flies the path; the check says which rule it used
    and agrees with the run; the follow_path made in the air is flown as it is."""
    script = tmp_path / "take_off_by_path.py"
    script.write_text(PYTHON_INTERFACE_TAKE_OFF_BY_PATH)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert "take_off_by_path.py:2:1: warning: follow_path from the ground takes off by its path, as Aerostack2 " \
           "before December 2022 did" in flight.err
    assert flight.achieved() == [T, F, F, L]
    activated = [(r["behavior"], r["detail"]) for r in flight.kinds("activated") if r["behavior"] in (T, F)]
    assert activated[0] == (T, "ALTITUDE=2.5")  # then the path's one point, reached: achieved at once
    assert [b for b, _ in activated] == [T, F]  # no take-off before the path flown in the air
    landed = flight.kinds("drone_landed")
    assert landed and landed[-1]["time"] > flight.kinds("drone_takeoff_complete")[0]["time"]


def test_a_python_interface_follow_path_from_the_ground_needs_an_armed_drone(tmp_path, capsys):
    """Then, a drone not armed and in offboard mode did not move (as2_core 6959a15): the script is refused."""
    script = tmp_path / "never_armed.py"
    script.write_text(PYTHON_INTERFACE_TAKE_OFF_BY_PATH.replace("uav.arm()\n", ""))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "never_armed.py:2:1: warning: follow_path from the ground took off by its path in Aerostack2 before " \
           "December 2022 (this script imports python_interface) only on a drone armed and in offboard mode" \
           in flight.err
    assert "never_armed.py:7:1: error: WRONG_SEQUENCE: The execution of behavior FOLLOW_PATH cannot be done at " \
           "the start of the mission (flight is landed; FOLLOW_PATH needs hovering or moving)" in flight.err


def test_a_python_interface_follow_path_takes_off_by_the_drone_s_state_in_flight(tmp_path, capsys):
    """In a loop the check cannot tell the flight's state at the call (it reports nothing); the run takes off by the
    drone's own: on the ground at the first pass, in the air at the second."""
    script = tmp_path / "in_a_loop.py"
    script.write_text(PYTHON_INTERFACE_TAKE_OFF_BY_PATH.replace(
        "uav.follow_path([[0, 0, 2.5]], 1)\n", "for altitude in (2, 3):\n    uav.follow_path([[0, 0, altitude]], 1)\n"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, F, F, F, L]
    activated = [(r["behavior"], r["detail"]) for r in flight.kinds("activated") if r["behavior"] in (T, F)]
    assert activated[0] == (T, "ALTITUDE=2") and activated[1][0] == F and "PATH=((0, 0, 3),)" in activated[1][1]


def test_a_python_interface_follow_path_after_a_landing_is_refused_as_the_run_would(tmp_path, capsys):
    """A landing disarms the drone (then, by the land behavior, as here): a follow_path after it would not move it, so
    the check does not take off for it, and says so before flight."""
    script = tmp_path / "after_landing.py"
    script.write_text(PYTHON_INTERFACE_TAKE_OFF_BY_PATH.replace("uav.land(0.3)\n",
                                                               "uav.land(0.3)\nuav.follow_path([[0, 0, 2]], 1)\n"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "after_landing.py:11:1: error: WRONG_SEQUENCE: The execution of behavior FOLLOW_PATH cannot be done after " \
           "the execution of LAND" in flight.err


def test_a_python_interface_go_to_from_the_ground_is_still_refused(tmp_path, capsys):
    """go_to rejected a goal on the ground from 2022-11-17 (goto_behaviour bd5740a), while the package was still
    python_interface: no earlier rule is given it."""
    script = tmp_path / "go_to_first.py"
    script.write_text(PYTHON_INTERFACE_TAKE_OFF_BY_PATH.replace("uav.follow_path([[0, 0, 2.5]], 1)",
                                                               "uav.go_to(0, 0, 2.5, 1)"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "go_to_first.py:8:1: error: WRONG_SEQUENCE: The execution of behavior GO_TO_POINT cannot be done at " \
           "the start of the mission" in flight.err
    assert "takes off by its path" in flight.err  # the script follows a path later: the rule is named, not used


def test_motion_references_on_the_ground_are_refused_and_the_run_says_so(tmp_path, capsys):
    flight = fly(SCRIPTS / "rosconches24_example1.py", tmp_path, capsys)  # never takes off
    assert flight.status == 3, flight.err  # completed with refused requests
    refused = flight.kinds("failed_preconditions")
    assert refused[0]["behavior"] == G and "?x1 = landed" in refused[0]["detail"]


#: A swarm script whose drones' namespaces are made as it runs: its source names none of them.
MADE_NAMES = """import rclpy
from as2_python_api.drone_interface import DroneInterface

rclpy.init()
drones = [DroneInterface(f"uav{i}", verbose=False) for i in range(2)]
for drone in drones:
    drone.arm()
"""


def test_a_multi_drone_script_flown_alone_says_it_needs_a_fleet(tmp_path, capsys, monkeypatch):
    # the scripts whose namespaces their source names fly as a fleet made for them (test_aerostack2_fleet.py);
    # one that makes its namespaces as it runs still says what it needs
    monkeypatch.setattr("builtins.input", lambda prompt="": "y")
    script = tmp_path / "made_names.py"
    script.write_text(MADE_NAMES)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1
    assert "and this run flies one drone: fly it as a fleet, one drone per namespace" in flight.err
    assert not [r for r in flight.kinds("activated") if r.get("source") == "mission"]  # nothing flew


REPLAY = '''\
import rclpy
from as2_python_api.drone_interface import DroneInterface


def confirm(msg="Continue"):
    return input(f"{msg}? (y/n): ") == "y"


rclpy.init()
drone = DroneInterface("drone0")
if confirm("Takeoff"):
    drone.takeoff(2.0, 1.0)
    drone.go_to(3, 0, 2, speed=1.0)
    while confirm("Replay"):
        drone.go_to(0, 3, 2, speed=1.0)
    if confirm("Land"):
        drone.land(0.5)
rclpy.shutdown()
'''


def test_a_replay_question_nobody_answers_replays_once_and_the_mission_completes(tmp_path, capsys, caplog):
    """``while confirm("Replay")`` with nobody there: "y" the first time, "n" when asked again (an operator who
    walked away asks for no more replays), so the script lands instead of replaying until the battery."""
    script = tmp_path / "mission.py"
    script.write_text(REPLAY)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert [b for b in flight.achieved() if b != "ASK_OPERATOR"] == [T, G, G, L]  # one replay, then the landing
    said = [r["detail"] for r in flight.records if r["kind"] == "operator" and r["detail"].startswith("Replay")]
    assert [d for d in said if d != "Replay? (y/n):"] == ["Replay? (y/n): y", "Replay? (y/n): n"], said
    assert "'Replay? (y/n):' asked again: answering 'n'" in caplog.text
    assert flight.kinds("run_ended")[-1]["detail"] == "completed"


#: A mission-interpreter script as Aerostack2's were written in spring 2023: the go_to module's x, y, z spelled
#: _x, _y, _z (as until May 2024), and ``perform_mission(debug)`` (March to May 2023).
INTERPRETER_2023 = '''\
import rclpy
from as2_python_api.mission_interpreter.mission import Mission
from as2_python_api.mission_interpreter.mission_interpreter import MissionInterpreter

PLAN = """{"target": "drone0", "plan": [
    {"behavior": "takeoff", "args": {"height": 2.0, "speed": 1.0}},
    {"behavior": "go_to", "args": {"_x": 4.0, "_y": -3.0, "_z": 2.0, "speed": 1.0, "yaw_mode": 1}},
    {"behavior": "land", "args": {"speed": 0.5}}]}"""

rclpy.init()
interpreter = MissionInterpreter(mission=Mission.parse_raw(PLAN))
ARM
interpreter.perform_mission(debug=DEBUG)
interpreter.shutdown()
rclpy.shutdown()
'''


@pytest.mark.parametrize("debug", [True, False])
def test_a_2023_interpreter_script_flies_its_underscored_points(debug, tmp_path, capsys):
    """debug=True: the script armed and switched to offboard itself; debug=False: the interpreter of 2023 did."""
    arm = "interpreter.drone.arm()\ninterpreter.drone.offboard()" if debug else ""
    script = tmp_path / "mission_planner.py"
    script.write_text(INTERPRETER_2023.replace("ARM", arm).replace("DEBUG", str(debug)))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, L]
    go_to = [r for r in flight.kinds("activated") if r["behavior"] == G][0]
    assert "COORDINATES=(4.0, -3.0, 2.0)" in go_to["detail"]  # _x, _y, _z
    armed = [r for r in flight.kinds("drone_command") if r["behavior"] == "ARM"]
    take_off = [r for r in flight.kinds("activated") if r["behavior"] == T][0]
    assert len(armed) == 1 and armed[0]["time"] <= take_off["time"], flight.kinds("drone_command")


def test_the_underscored_spelling_is_checked_before_flight_as_the_other(tmp_path, capsys):
    script = tmp_path / "mission.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n\nrclpy.init()\n"
                      "drone = DroneInterface('drone0')\ndrone.arm()\ndrone.offboard()\ndrone.takeoff(2.0, 1.0)\n"
                      "drone.go_to(_x=1.0, _y=2.0, _w=2.0, speed=1.0)\ndrone.land()\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1
    assert "mission.py:9:1: error: WRONG_FORMAT: go_to() has no argument _w" in flight.err, flight.err
