"""``aeroexec verify`` knows Aerostack2's Python API as it knows Aerostack's: wrong methods, arguments, values and
flight order are errors at their line before take-off; values reach the calls through names bound once; ROS 2
beyond the drone interface is refused where it is used. The missions here are ours."""

from __future__ import annotations

import textwrap

from aeroexec.drones.sim import default_world
from aeroexec.engine.missions.check import check_mission_source

HEADER = """import rclpy
from as2_python_api.drone_interface import DroneInterface
"""


def problems(body: str, world=None, header: str = HEADER, indent: str = "") -> list[tuple[int, str, str]]:
    source = header + textwrap.indent(textwrap.dedent(body).lstrip("\n"), indent)
    found = check_mission_source(source, "mission.py", world=world)
    return [(p.line, p.severity, p.message) for p in found]


def test_an_aerostack2_script_runs_whole_and_is_checked_from_its_first_line():
    assert problems("""
        rclpy.init()
        uav = DroneInterface("drone0")
        uav.takeoff(2.0, 1.0)
        uav.go_to.go_to_point([1, 1, 2], speed=1.0)
        uav.land()
        """) == []


def test_methods_and_arguments_aerostack2_does_not_have_are_errors_at_their_line():
    assert problems("""
        uav = DroneInterface("drone0")
        uav.take_off(2.0)
        uav.go_to.go_to_pont([1, 1, 2], 1.0)
        uav.go_to(1, 2)
        uav.land(speed=0.5, height=3)
        uav.follow_path([[1, 1, 2]], 1.0, 0, None, None, True, 7)
        """) == [
        (4, "error", "The function take_off does not exist in Aerostack2's DroneInterface (did you mean takeoff?)"),
        (5, "error", "The method go_to_pont does not exist in Aerostack2's go_to module (did you mean go_to_point?)"),
        (6, "error", "go_to() needs argument z"),
        (7, "error", "land() has no argument height (its arguments: speed, wait)"),
        (8, "error", "follow_path() takes 6 arguments (path, speed, yaw_mode, yaw_angle, frame_id, wait), 7 given"),
    ]


def test_a_member_named_otherwise_than_its_module_is_named_as_the_script_wrote_it():
    """project_px4_controller_tuning calls a DroneInterfaceGPS's follow_path() with no path: Aerostack2's
    follow_path_gps module there, a TypeError under python3; the error names what the script wrote."""
    header = "import rclpy\nfrom as2_python_api.drone_interface_gps import DroneInterfaceGPS\n"
    assert problems("""
        uav = DroneInterfaceGPS("drone0")
        uav.takeoff(2.0, 1.0)
        uav.follow_path()
        """, header=header) == [(5, "error", "follow_path() (DroneInterfaceGPS.follow_path is Aerostack2's "
                                             "follow_path_gps module) needs argument geopath")]


def test_values_are_checked_at_the_argument_that_gave_them():
    found = check_mission_source(HEADER + textwrap.dedent("""\
        uav = DroneInterface("drone0")
        uav.takeoff(height=800, speed=1.0)
        uav.go_to(0, 0, 2, speed=0)
        """), "mission.py")
    assert [(p.line, p.column, p.kind, p.message.split(" (")[0]) for p in found] == [
        (4, 20, "WRONG_VALUE", "The value 800 of argument ALTITUDE for behavior TAKE_OFF is not correct"),
        (5, 26, "WRONG_VALUE", "The value 0 of argument SPEED for behavior GO_TO_POINT is not correct"),
    ]


def test_flight_order_is_checked_through_the_scripts_own_functions():
    assert problems("""
        def drone_start(drone_interface: DroneInterface) -> bool:
            drone_interface.arm()
            drone_interface.offboard()
            return True

        def drone_run(drone_interface: DroneInterface) -> None:
            drone_interface.go_to(1, 1, 2, 1.0)

        if __name__ == "__main__":
            uav = DroneInterface(drone_id="drone0")
            if drone_start(uav):
                drone_run(uav)
            uav.land()
        """) == [
        (9, "error", "The execution of behavior GO_TO_POINT cannot be done at the start of the mission (flight is "
                      "landed; GO_TO_POINT needs hovering or moving)"),
    ]


def test_a_drone_passed_to_a_function_with_no_annotation_is_checked_as_the_drone():
    """project_f330_test's ``drone_run(drone_interface)``, called with the drone interface: its follow_path from the
    ground was refused in flight (a run "completed with refused requests"), not before it."""
    assert problems("""
        def drone_run(drone_interface, speed):
            drone_interface.follow_path([[0.1, 0.0, 1.0]], speed=speed)
            drone_interface.go_too(1, 1, 2, 1.0)

        def not_a_drone(thing):
            thing.go_too(1, 1, 2)

        if __name__ == "__main__":
            uav = DroneInterface("drone_0")
            drone_run(uav, speed=0.5)
            not_a_drone(uav)
            not_a_drone("a string")
        """) == [
        (4, "error", "The execution of behavior FOLLOW_PATH cannot be done at the start of the mission (flight is "
                      "landed; FOLLOW_PATH needs hovering or moving)"),
        (5, "error", "The function go_too does not exist in Aerostack2's DroneInterface (did you mean go_to?)"),
    ]


GATES = """
    def go_through(drone_interface: DroneInterface, point, frame_id):
        drone_interface.go_to.go_to_point_path_facing(point=point, speed=1.0, frame_id=frame_id)

    uav = DroneInterface("cf0")
    uav.takeoff(2.0, 0.7)
    gates = {"gate_0/link": [1.0, 0.0, 2.0], "gate_1/link": [-1.0, 0.0, 2.0]}
    for gate, point in gates.items():
        go_through(uav, point, gate)
    uav.land()
    """


def test_a_frame_built_at_run_time_from_tf_frames_the_script_names_is_refused_before_flight():
    """project_crazyflie_gates: gates given as frames of ROS 2's tf tree, reaching go_to through a dict; each
    request was refused in flight, after the take-off, and the run ended failed some 8 s later."""
    assert problems(GATES) == [
        (4, "error", "The frame of go_to.go_to_point_path_facing() is not known before flight, and the script names "
                     "frames of ROS 2's tf tree ('gate_0/link' (line 8), 'gate_1/link' (line 8)): aeroexec flies in "
                     "the earth frame (local ENU from home); frames of ROS 2's tf tree are not available (this "
                     "mission uses ROS 2 beyond the drone interface)"),
    ]


def test_a_frame_given_straight_to_a_call_does_not_make_another_unknown_frame_an_error():
    assert problems(GATES.replace('gates = {"gate_0/link": [1.0, 0.0, 2.0], "gate_1/link": [-1.0, 0.0, 2.0]}',
                                  'gates = {"earth": [1.0, 0.0, 2.0]}\n    '
                                  'print(uav.base_frame_id == str("cf0/base_link"))')) == []


def test_a_destination_through_a_name_bound_once_is_checked_against_the_world():
    found = check_mission_source(HEADER + textwrap.dedent("""\
        HEIGHT = 2.0
        TOWER = [8, 8, HEIGHT]
        uav = DroneInterface("drone0")
        uav.takeoff(HEIGHT)
        uav.go_to.go_to_point(TOWER, 1.0)
        uav.land()
        """), "mission.py", world=default_world())
    assert [(p.line, p.column, p.kind, p.message) for p in found] == [
        (7, 23, "WRONG_VALUE", "The value (8, 8, 2.0) of argument COORDINATES for behavior GO_TO_POINT is not "
                               "correct: (8, 8, 2) is 0.0 m from tower; GO_TO_POINT needs 3 m")]


def test_a_levant_destination_through_a_variable_is_refused_as_the_literal_is():
    header = "import executive_engine_api as api\n\n\ndef runMission():\n"
    through_variable = problems("""
        endPoint = [8, 8, 0.7]
        api.executeBehavior('TAKE_OFF')
        api.executeBehavior('GO_TO_POINT', coordinates=endPoint)
        """, world=default_world(), header=header, indent="    ")
    inline = problems("""
        api.executeBehavior('TAKE_OFF')
        api.executeBehavior('GO_TO_POINT', coordinates=[8, 8, 0.7])
        """, world=default_world(), header=header, indent="    ")
    assert [m for _, _, m in through_variable] == [m for _, _, m in inline] != []
    assert "(8, 8, 0.7) is 0.0 m from tower; GO_TO_POINT needs 3 m" in through_variable[0][2]


def test_a_name_bound_twice_or_in_a_loop_is_left_to_the_run():
    assert problems("""
        uav = DroneInterface("drone0")
        height = 2.0
        height = 80
        uav.takeoff(height)
        for goal in [[1, 1, 2], [200, 0, 2]]:
            uav.go_to.go_to_point(goal, 1.0)
        uav.land()
        """) == []


def test_ros_2_beyond_the_drone_interface_is_refused_where_it_is_used():
    found = problems("""
        from rclpy.node import Node
        from std_msgs.msg import String
        from geometry_msgs.msg import PoseStamped

        class Mine(DroneInterface):
            def listen(self):
                self.create_subscription(String, "chatter", print, 10)

        rclpy.init()
        uav = Mine("drone0")
        rclpy.spin_once(uav)
        rclpy.shutdown()
        """)
    assert found == [
        # ROS 2's messages are data now (issue 42): PoseStamped and String are served; the subscription is refused;
        # a script's own node and spinning are served (rclpy.node.Node, rclpy.spin_once: aerostack2/rclpy/node.py)
        (9, "error", "DroneInterface.create_subscription: this mission uses ROS 2 beyond the drone interface (a "
                     "subscription to chatter, which another program publishes)"),
    ]


NEVER_ENDS = ("This mission never ends: the loop `while True:` has no break, return or exit, so the drone would fly "
              "on until the battery runs low; give the loop an end (a count, a duration or a condition)")


def test_a_while_true_loop_with_no_way_out_after_take_off_is_refused_at_its_line():
    """pariaspe/project_gazebo's mission_vel_motion_ref.py: speed references sent forever, in a method of the
    drone's class that took off; and the same loop at the script's top level."""
    assert problems("""
        import time

        class Drone(DroneInterface):
            def run(self):
                self.takeoff(1.0, wait=True)
                while True:
                    self.motion_ref_handler.speed.send_speed_command_with_yaw_angle([0.5, 0.0, 0.0])
                    time.sleep(0.1)

        uav = Drone("drone0")
        uav.run()
        while True:
            time.sleep(1)
        """) == [(8, "error", NEVER_ENDS), (14, "error", NEVER_ENDS)]


def test_loops_with_a_way_out_or_in_a_thread_that_flies_nothing_are_not_refused():
    assert problems("""
        import sys
        import threading
        import time

        def watch():
            while True:
                print("alive")
                time.sleep(1)

        threading.Thread(target=watch, daemon=True).start()
        uav = DroneInterface("drone0")
        uav.takeoff(2.0, 1.0)
        while True:
            for _ in range(3):
                break
            if uav.info["state"] == 0:
                break
        while 1:
            uav.go_to(1, 1, 2, 1.0)
            sys.exit(0)
        """) == []


READS = """
    import csv

    def load_path_from_csv(file_path):
        with open(file_path, newline='') as csvfile:
            return [[float(row['x']), float(row['y']), float(row['z'])] for row in csv.DictReader(csvfile)]

    PATH = load_path_from_csv("config/joints.csv")
    uav = DroneInterface("drone0")
    uav.takeoff(1.0, 1.0)
    uav.follow_path(PATH, 1.0)
    with open("notes.txt", "w") as notes:
        notes.write("done")
    """


def test_a_file_the_script_reads_that_is_not_there_is_refused_naming_it(tmp_path, monkeypatch):
    """jackha02/project_gazebo's jacket_inspection_single.py reads config/joints.csv from the folder it is run
    in: refused before flight naming the file and the folder, where it failed at t=0 with a traceback's line."""
    monkeypatch.chdir(tmp_path)
    assert problems(READS) == [(9, "error", f"The script reads the file config/joints.csv, which is not there (from "
                                            f"the folder {tmp_path}): the mission would stop at this line; run it "
                                            f"from the folder that holds config/joints.csv, as under python3")]
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "joints.csv").write_text("x,y,z\n1,0,1\n")
    assert problems(READS) == []  # run from the project's folder, as its author does; a file written is not read


def test_a_script_that_waits_for_drones_another_program_flies_is_refused_at_their_interface():
    """rss24_demo's mission_leader.py waits for its followers (DroneInterfaceBase, flown by mission_follower.py)
    to take off: run alone it waited until the 1,800 s limit; now refused before flight, saying what it needs."""
    found = problems("""
        from time import sleep
        from as2_msgs.msg import PlatformStatus
        from as2_python_api.drone_interface import DroneInterfaceBase

        def wait_to_takeoff(drone_interface):
            while drone_interface.info['state'] != PlatformStatus.FLYING:
                sleep(1.0)

        leader = DroneInterface("drone0")
        follower = DroneInterfaceBase(drone_id="drone1")
        leader.takeoff(1.0, 0.5)
        wait_to_takeoff(follower)
        leader.land(0.3)
        """)
    assert found == [(12, "error", "DroneInterfaceBase only watches its drone: nothing in this script flies it (no "
                                   "behavior module is given it), and the script waits for a drone's state (the loop "
                                   "at line 8); another program flies that drone. Fly them together, each drone with "
                                   "its own program, in a fleet file (aeroexec fleet)")]


def test_a_drone_interface_base_given_a_module_flies_and_is_not_refused():
    assert problems("""
        from as2_python_api.drone_interface_base import DroneInterfaceBase
        from as2_python_api.modules.motion_reference_handler_module import MotionReferenceHandlerModule

        uav = DroneInterfaceBase(drone_id="drone0")
        uav.motion_ref_handler = MotionReferenceHandlerModule(drone=uav)
        while uav.info['state'] != 2:
            uav.motion_ref_handler.hover()
        """) == []
