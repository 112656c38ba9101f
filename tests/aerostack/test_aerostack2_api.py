"""Aerostack2's Python API over aeroexec keeps Aerostack2's conventions: True/False results, non-blocking calls
polled through ``status``, ``stop()``, ``info``, the engine's clock behind ``time``; what it cannot serve is
refused with the reason, at the mission's line. The scripts here are ours, written as Aerostack2's are."""

from __future__ import annotations

import textwrap

import pytest
from flying import fly, world

HEADER = """
import time
from time import sleep

import rclpy
from as2_msgs.msg import BehaviorStatus, PlatformStatus
from as2_python_api.drone_interface import DroneInterface

rclpy.init()
uav = DroneInterface("drone0", verbose=False)
"""


def script(tmp_path, body: str, name: str = "mission.py"):
    path = tmp_path / name
    path.write_text(HEADER + textwrap.dedent(body))
    return path


def test_calls_return_what_aerostack2_returns(tmp_path, capsys):
    path = script(tmp_path, """
        print("land", getattr(uav, "la" + "nd")(0.5))  # on the ground: refused (verify cannot see this one)
        print("state", uav.info["state"] == PlatformStatus.DISARMED, uav.info["armed"])
        print("arm", uav.arm(), uav.arm(), uav.offboard(), uav.offboard())
        print("takeoff", uav.takeoff(2.0, 1.0), uav.info["state"] == PlatformStatus.FLYING)
        print("result", uav.takeoff.result, uav.takeoff.status == BehaviorStatus.IDLE)
        print("go_to", uav.go_to(3, 0, 2, 1.0), [round(p) for p in uav.position])
        print("disarm", uav.disarm())  # flying: refused
        print("land", uav.land(0.5), uav.disarm(), uav.info["armed"])
        uav.shutdown()
        rclpy.shutdown()
        """)
    flight = fly(path, tmp_path, capsys)
    assert flight.status == 3, flight.err  # the first landing was refused: completed with refused requests
    lines = flight.out.splitlines()
    for expected in ("land False", "state True False", "arm True True True True", "takeoff True True",
                     "result True True", "go_to True [3, 0, 2]", "disarm False", "land True True False"):
        assert expected in lines, flight.out
    assert [(r["behavior"], r["detail"]) for r in flight.kinds("drone_command")] == [
        ("ARM", "done"), ("DISARM", "disarm denied: the drone is flying (land first)"), ("DISARM", "done")]


def test_a_call_not_waited_for_is_polled_through_status_and_can_be_stopped(tmp_path, capsys):
    path = script(tmp_path, """
        uav.takeoff(2.0, 1.0)
        print("started", uav.go_to(0, 20, 2, 0.5, wait=False), uav.go_to.status == BehaviorStatus.RUNNING)
        start = time.time()
        while uav.go_to.status == BehaviorStatus.RUNNING and time.time() - start < 4:
            sleep(0.1)
        print("stopped", uav.go_to.stop(), uav.go_to.status == BehaviorStatus.IDLE, uav.go_to.result)
        print("waited", round(time.time() - start, 1))
        print("again", uav.go_to(0, 2, 2, 1.0, wait=False), uav.go_to.wait_to_result(), uav.go_to.result)
        uav.land()
        """)
    flight = fly(path, tmp_path, capsys)
    assert flight.status == 0, flight.err
    lines = flight.out.splitlines()
    assert "started True True" in lines and "stopped True True False" in lines and "again True True True" in lines
    assert "waited 4.0" in lines  # time.time() and sleep are the engine's clock
    stopped = [r for r in flight.kinds("INTERRUPTED") if r["behavior"] == "GO_TO_POINT"]
    assert stopped and stopped[0]["detail"] == "stopped by the mission"


def test_what_the_drone_cannot_serve_is_refused_with_the_reason_and_the_run_says_so(tmp_path, capsys):
    path = script(tmp_path, """
        uav.takeoff(2.0, 1.0)
        speed = float("100")  # computed: verify leaves it to the run
        print("far", uav.go_to(0, 0, 2, speed))
        print("frame", uav.go_to(1, 0, 2, 1.0, frame_id="drone0/" + "base_link"))
        print("yaw", uav.go_to(1, 0, 2, 1.0, yaw_mode=int("4")))
        uav.land()
        """)
    flight = fly(path, tmp_path, capsys)
    assert flight.status == 3, flight.err
    assert {"far False", "frame False", "yaw False"} <= set(flight.out.splitlines())
    reasons = [(r["behavior"], r["detail"], r["data"].get("where")) for r in flight.kinds("rejected")]
    assert reasons[0][0] == "GO_TO_POINT" and "The value 100.0 of argument SPEED" in reasons[0][1]
    assert reasons[0][2] == "mission.py:14"
    assert reasons[1][0] == "go_to" and "frames of ROS 2's tf tree are not available" in reasons[1][1]
    assert reasons[2][0] == "go_to" and "modes 3 to 6 follow ROS 2 topics and frames" in reasons[2][1]


def test_ros_2_beyond_the_drone_interface_fails_the_run_at_its_line(tmp_path, capsys):
    path = script(tmp_path, """
        uav.takeoff(2.0, 1.0)
        listen = getattr(uav, "create_" + "subscription")  # computed: verify cannot see it
        listen("String", "chatter", print, 10)
        """)
    flight = fly(path, tmp_path, capsys)
    assert flight.status == 1
    failed = flight.kinds("mission_failed")[0]["detail"]
    assert "mission.py at mission.py:14: RosFeatureError: DroneInterface.create_subscription: this mission uses " \
           "ROS 2 beyond the drone interface" in failed
    assert flight.kinds("GOAL_ACHIEVED")[-1]["behavior"] == "LAND"  # the run landed the drone left in the air


def test_an_origin_elsewhere_is_refused_and_the_home_point_accepted(tmp_path, capsys):
    path = tmp_path / "gps.py"
    path.write_text(textwrap.dedent("""
        import rclpy
        from as2_python_api.drone_interface_gps import DroneInterfaceGPS
        rclpy.init()
        uav = DroneInterfaceGPS("drone0")
        print("origin", uav.gps.origin)
        print("here", uav.gps.set_origin([10.0, 20.0, 0.0]))
        print("there", uav.gps.set_origin([10.5, 20.0, 0.0]))
        """))
    flight = fly(path, tmp_path, capsys, world_file=world(tmp_path, 10.0, 20.0, 5.0))
    assert flight.status == 3, flight.err
    assert {"origin [10.0, 20.0, 5.0]", "here True", "there False"} <= set(flight.out.splitlines())
    assert "the earth frame is fixed at home" in flight.kinds("rejected")[0]["detail"]


@pytest.mark.parametrize("ending, status", [("exit(0)", 0), ("import sys\nsys.exit(2)", 1)])
def test_the_scripts_exit_status_says_how_the_mission_ended(ending, status, tmp_path, capsys):
    path = script(tmp_path, f"uav.takeoff(1.0)\nuav.land()\n{ending}\nprint('not reached')\n")
    flight = fly(path, tmp_path, capsys)
    assert flight.status == status, flight.err
    assert "not reached" not in flight.out
    if status:
        assert "the script exited with status 2" in flight.kinds("mission_failed")[0]["detail"]


def test_threads_of_the_scripts_own_are_the_missions(tmp_path, capsys):
    path = script(tmp_path, """
        import threading

        def fly():
            uav.takeoff(2.0, 1.0)
            sleep(3)  # a thread's sleep is on the engine's clock too
            uav.go_to(2, 0, 2, 1.0)

        worker = threading.Thread(target=fly)
        started = time.time()
        worker.start()
        worker.join()  # simulated time moves while the mission only waits for its thread
        print("joined after", round(time.time() - started))
        uav.land()
        """)
    flight = fly(path, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == ["TAKE_OFF", "GO_TO_POINT", "LAND"]
    # the join waited the simulated seconds its thread flew (take-off 1.75 s, 3 s, go_to 2.1 s), and not a step more:
    # the joiner runs again from its thread's end, not from when it wakes (late on a loaded machine, and once the
    # clock ran on while it woke: 6.85 s, 17.5 s, 23.7 s seen at load 4)
    assert "joined after 7" in flight.out.splitlines(), flight.out


def test_a_joined_thread_s_end_hands_its_running_to_the_joiner_before_the_joiner_wakes():
    from aeroexec.engine.missions.bridge import DONE, RUNNING, MissionBridge

    bridge, worker = MissionBridge(), object()
    bridge.mission_started()  # the script's main thread runs
    bridge.thread_started(worker)
    assert bridge.joining(worker) and bridge.state == RUNNING  # the worker runs, the main thread waits for it
    bridge.thread_ended(worker)
    assert bridge.state == RUNNING  # the main thread runs from here on, though it has not woken yet
    bridge.joined(worker)
    assert bridge.state == RUNNING and bridge._mission.running == 1  # counted once
    assert not bridge.joining(worker)  # joining a thread that has ended: the joiner runs on
    bridge.thread_started(worker := object())
    assert bridge.joining(worker) and bridge._mission.running == 1
    bridge.joined(worker)  # a join whose timeout passed: the joiner runs again, the worker still does
    assert bridge._mission.running == 2
    bridge.thread_ended(worker)
    assert bridge._mission.running == 1
    bridge.mission_finished()
    assert bridge.state == DONE
