"""A script's own ROS 2 node (``rclpy.node.Node``): its parameters (defaults, ``--ros-args -p`` given after
``aeroexec run script.py --``), its clock and timers, whose callbacks the spin runs on the engine's clock, and
``rclpy.shutdown()`` from a callback ending the spin. What needs a ROS 2 graph (a subscription, a client) is still
refused before flight at its line, and a spin nothing can end is refused, or ends with its reason, never hangs.

The scripts here are ours, written for these tests in the style of Aerostack2's examples (a Node subclass driving
a DroneInterface); none was collected from a project."""

from __future__ import annotations

import textwrap

import pytest
from aeroexec.dialects.aerostack2.rclpy.context import RosArgumentError, ros_arguments
from aeroexec.engine.missions.check import check_mission_source
from flying import EMPTY_WORLD, fly

T, G, L = "TAKE_OFF", "GO_TO_POINT", "LAND"

# ours (not collected): a timer-driven mission in the style of Aerostack2's examples
SQUARE = '''#!/usr/bin/env python3
"""Square mission driven by a timer (written for aeroexec's tests)."""

import rclpy
from rclpy.node import Node
from as2_python_api.drone_interface import DroneInterface


class SquareMission(Node):
    """Flies a square, one step per tick of its timer."""

    def __init__(self, drone):
        super().__init__('square_mission', namespace=drone.drone_id)
        self.declare_parameter('height', 2.0)
        self.declare_parameter('side', 4.0)
        self.declare_parameter('speed', 1.0)
        self.height = self.get_parameter('height').value
        self.side = self.get_parameter('side').get_parameter_value().double_value
        self.speed = self.get_parameter('speed').value
        self.drone = drone
        self.step = 0
        self.ticks = []
        self.timer = self.create_timer(0.5, self.tick)

    def tick(self):
        self.ticks.append(self.get_clock().now().nanoseconds)
        s = self.side
        square = [[s, 0.0], [s, s], [0.0, s], [0.0, 0.0]]
        if self.step == 0:
            self.drone.arm()
            self.drone.offboard()
            self.drone.takeoff(self.height, speed=self.speed)
        elif self.step <= len(square):
            x, y = square[self.step - 1]
            self.drone.go_to.go_to_point([x, y, self.height], speed=self.speed)
        else:
            self.drone.land(speed=0.5)
            self.timer.cancel()
            rclpy.shutdown()
        self.step += 1


def main():
    rclpy.init()
    drone = DroneInterface('drone0', verbose=False)
    mission = SquareMission(drone)
    rclpy.spin(mission)
    assert mission.ticks[0] == 500_000_000, mission.ticks  # the first tick a period after the timer was made
    assert not rclpy.ok()
    mission.destroy_node()
    rclpy.try_shutdown()


if __name__ == '__main__':
    main()
'''


def fly_given(script, tmp_path, capsys, *script_args):
    """``aeroexec run script --world ... -- SCRIPT_ARGS``: the script's own arguments after a lone --."""
    return fly(script, tmp_path, capsys, "--world", str(EMPTY_WORLD), "--", *script_args, world_file=None)


def test_a_timer_driven_node_flies_its_mission_and_shutdown_in_a_callback_ends_the_spin(tmp_path, capsys):
    script = tmp_path / "square.py"
    script.write_text(SQUARE)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, G, G, G, L]
    assert "completed" in flight.out


def test_a_timer_in_a_callback_group_flies_and_a_subscription_is_refused_naming_its_topic(tmp_path, capsys):
    """Callback groups (rclpy.callback_groups) are data: a timer given one is served, the node's callbacks one at a
    time as either group allows. A subscription is still refused before flight, naming the topic another program
    would publish (project_gazebo's click-to-navigate: RViz's /clicked_point)."""
    grouped = SQUARE.replace("from rclpy.node import Node\n", "from rclpy.node import Node\n"
                             "from rclpy.callback_groups import MutuallyExclusiveCallbackGroup\n")
    grouped = grouped.replace("self.create_timer(0.5, self.tick)",
                              "self.create_timer(0.5, self.tick, callback_group=MutuallyExclusiveCallbackGroup())")
    script = tmp_path / "grouped.py"
    script.write_text(grouped)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, G, G, G, L]
    clicks = tmp_path / "clicks.py"
    clicks.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n"
                      "from geometry_msgs.msg import PointStamped\n\n\nclass Drone(DroneInterface):\n"
                      "    def __init__(self):\n        super().__init__('drone0')\n"
                      "        self.create_subscription(PointStamped, '/clicked_point', print, 10)\n")
    refused = fly(clicks, tmp_path, capsys)
    assert refused.status == 1 and not refused.records
    assert "clicks.py:9:9: error: WRONG_FORMAT: DroneInterface.create_subscription: this mission uses ROS 2 beyond " \
           "the drone interface (a subscription to /clicked_point, which another program publishes)" in refused.err


def test_parameters_given_with_ros_args_change_what_it_flies(tmp_path, capsys):
    """Declared defaults fly a 4 m square at 2 m; ``-- --ros-args -p height:=3.0 -p square_mission:side:=2.5``
    (the second for that node only, as rcl reads it) flies a 2.5 m square at 3 m."""
    script = tmp_path / "square.py"
    script.write_text(SQUARE)
    default = fly(script, tmp_path, capsys)
    given = fly_given(script, tmp_path / "given", capsys, "--ros-args", "-p", "height:=3.0", "-p",
                      "square_mission:side:=2.5")
    assert default.status == 0 and given.status == 0, given.err
    assert "COORDINATES=(4.0, 4.0, 2.0)" in default.out and "ALTITUDE=2.0" in default.out
    assert "COORDINATES=(2.5, 2.5, 3.0)" in given.out and "ALTITUDE=3.0" in given.out
    assert "4.0" not in "".join(line for line in given.out.splitlines() if "COORDINATES" in line)
    other = fly_given(script, tmp_path / "other", capsys, "--ros-args", "-p", "another_node:side:=2.5")
    assert "COORDINATES=(4.0, 4.0, 2.0)" in other.out  # another node's parameter is not this node's


def test_a_parameter_of_another_type_than_its_default_fails_at_the_declaration(tmp_path, capsys):
    """ROS 2's parameters are statically typed: ``-p side:=2`` is an integer, the default 4.0 a double."""
    script = tmp_path / "square.py"
    script.write_text(SQUARE)
    flight = fly_given(script, tmp_path, capsys, "--ros-args", "-p", "side:=2")
    assert flight.status == 1 and not flight.achieved()
    assert "square.py:15: InvalidParameterTypeException: Trying to set parameter 'side' to '2' of type 'INTEGER', " \
           "expecting type 'DOUBLE'" in flight.err + flight.out


def test_ros_arguments_as_rcl_reads_them(tmp_path):
    params = tmp_path / "params.yaml"
    params.write_text("/**:\n  ros__parameters:\n    speed: 0.5\nsquare_mission:\n  ros__parameters:\n"
                      "    gains: {p: 1.5}\n")
    found = ros_arguments(["square.py", "-n", "x", "--ros-args", "-p", "height:=3", "-p", "names:=[a, b]",
                           "-r", "__ns:=/drone1", "--params-file", str(params), "--", "--not-ros"])
    assert found.parameters == [(None, "height", 3), (None, "names", ["a", "b"]), ("/**", "speed", 0.5),
                                ("square_mission", "gains.p", 1.5)]
    assert found.for_node("square_mission", "/drone1/square_mission") == {"height": 3, "names": ["a", "b"],
                                                                           "speed": 0.5, "gains.p": 1.5}
    assert found.remapped("__ns", "square_mission", "/") == "/drone1"
    with pytest.raises(RosArgumentError, match="'--bogus'"):
        ros_arguments(["--ros-args", "--bogus"])


def check(source: str) -> list[tuple[int, str, str]]:
    return [(p.line, p.severity, f"{p.kind}: {p.message}" if p.kind else p.message)
            for p in check_mission_source(textwrap.dedent(source), "node.py")]


def test_a_subscription_of_a_node_is_still_refused_at_its_line(tmp_path, capsys):
    source = '''
        import rclpy
        from rclpy.node import Node
        from geometry_msgs.msg import PoseStamped


        class Follower(Node):
            def __init__(self):
                super().__init__('follower')
                self.create_subscription(PoseStamped, 'leader/pose', self.on_pose, 10)
                self.create_timer(0.5, self.tick)

            def on_pose(self, msg):
                self.pose = msg

            def tick(self):
                rclpy.shutdown()


        rclpy.init()
        node = Follower()
        client = node.create_client(PoseStamped, 'x')
        rclpy.spin(node)
        '''
    beyond = "this mission uses ROS 2 beyond the drone interface"
    assert check(source) == [(3, "error", "WRONG_FORMAT: Nothing in this script flies a drone: it uses no drone "
                                          "interface of Aerostack2's Python API (as2_python_api's DroneInterface), "
                                          "so run alone, under python3 too, the drone stays on the ground. It makes "
                                          "ROS 2 nodes of its own and no drone interface"),
                             (10, "error", f"WRONG_FORMAT: Node.create_subscription: {beyond}"),
                             (22, "error", f"WRONG_FORMAT: Node.create_client: {beyond}")]
    script = tmp_path / "follower.py"
    script.write_text(textwrap.dedent(source))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert f"follower.py:10:9: error: WRONG_FORMAT: Node.create_subscription: {beyond}" in flight.err


IDLE = '''
    import rclpy
    from rclpy.node import Node
    from as2_python_api.drone_interface import DroneInterface


    class Idle(Node):
        def __init__(self):
            super().__init__('idle')


    def make():
        return Idle()


    rclpy.init()
    uav = DroneInterface('drone0')
    uav.arm()
    uav.offboard()
    uav.takeoff(2.0, 1.0)
    node = {node}
    rclpy.spin(node)
    uav.land(0.5)
    '''


def test_a_spin_of_a_node_with_no_timer_is_refused_before_flight_as_a_loop_with_no_way_out(tmp_path, capsys):
    script = tmp_path / "idle.py"
    script.write_text(textwrap.dedent(IDLE.format(node="Idle()")))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "idle.py:22:1: error: WRONG_SEQUENCE: This mission never ends: rclpy.spin() runs its node's callbacks " \
           "until rclpy.shutdown(), and the script gives it none (no create_timer)" in flight.err


def test_a_spin_the_check_cannot_see_ends_at_once_with_its_reason(tmp_path, capsys):
    """The node made by a function: the check does not follow it, the spin fails at once (not at the time limit)."""
    script = tmp_path / "idle.py"
    script.write_text(textwrap.dedent(IDLE.format(node="make()")))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and flight.achieved() == [T, L]  # the take-off; the run then lands the drone
    assert "idle.py:22: SpinNeverEnds: this spin never ends: its node (idle) has no timer, and no other thread of " \
           "the script runs to call rclpy.shutdown()" in flight.err + flight.out
    ended = flight.kinds("mission_failed")[0]
    assert ended["time"] < 60  # at the spin, some 7 s in: not at the time limit


def test_a_spin_whose_timers_never_shut_down_ends_at_the_time_limit(tmp_path, capsys):
    script = tmp_path / "ticking.py"
    script.write_text(textwrap.dedent('''
        import rclpy
        from rclpy.node import Node
        from as2_python_api.drone_interface import DroneInterface


        class Ticker(Node):
            def __init__(self):
                super().__init__('ticker')
                self.count = 0
                self.create_timer(1.0, self.tick)

            def tick(self):
                self.count += 1


        rclpy.init()
        uav = DroneInterface('drone0')
        uav.arm()
        uav.offboard()
        uav.takeoff(2.0, 1.0)
        rclpy.spin(Ticker())
        '''))
    flight = fly(script, tmp_path, capsys, "--max-time", "20")
    assert flight.status == 1
    assert "20 s of engine time have passed" in flight.out + flight.err
    assert flight.achieved() == [T, L]  # its take-off; the run lands the drone at the time limit


EXECUTORS = '''
    import rclpy
    from rclpy.executors import MultiThreadedExecutor
    from rclpy.node import Node
    from rclpy.task import Future
    from as2_python_api.drone_interface import DroneInterface
    from std_msgs.msg import String


    class Mission(Node):
        def __init__(self, uav, done):
            super().__init__('mission')
            self.uav, self.done = uav, done
            self.status = self.create_publisher(String, 'mission_status', 10)
            self.timer = self.create_timer(2.0, self.fly)

        def fly(self):
            self.timer.cancel()
            self.uav.arm()
            self.uav.offboard()
            self.uav.takeoff(2.0, 1.0)
            self.status.publish(String(data='up'))
            self.done.set_result(self.get_clock().now())


    rclpy.init()
    uav = DroneInterface('drone0')
    done = Future()
    node = Mission(uav, done)
    rclpy.spin_until_future_complete(node, done, timeout_sec=30.0)
    assert done.done() and done.result().nanoseconds >= 2_000_000_000
    waited = node.get_clock().now()
    rclpy.spin_once(node, timeout_sec=0.5)  # no timer left due within 0.5 s: it returns when that has passed
    assert (node.get_clock().now() - waited).nanoseconds >= 500_000_000

    class Lander(Node):
        def __init__(self):
            super().__init__('lander')
            self.timer = self.create_timer(1.0, self.land)

        def land(self):
            uav.land(0.5)
            self.destroy_timer(self.timer)
            executor.shutdown()


    executor = MultiThreadedExecutor()
    executor.add_node(Lander())
    executor.spin()
    rclpy.shutdown()
    '''


def test_executors_and_futures_run_the_nodes_timers_on_the_engines_clock(tmp_path, capsys):
    script = tmp_path / "executors.py"
    script.write_text(textwrap.dedent(EXECUTORS))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, L]
    assert [(r["behavior"], r["detail"]) for r in flight.kinds("published")] == [
        ("/mission_status", "std_msgs.msg.String(data='up')")]


def test_a_scripts_own_arguments_follow_a_lone_double_dash_on_run_only():
    from aeroexec.cli.main import build_parser

    argv = ["run", "mission.py", "--max-time", "5", "--", "-n", "drone1", "--ros-args", "-p", "height:=3.0", "--"]
    parsed = build_parser(argv).parse_args(argv)
    assert parsed.max_time == 5 and parsed.script_args == ["-n", "drone1", "--ros-args", "-p", "height:=3.0", "--"]
    assert build_parser(["run", "m.py"]).parse_args(["run", "m.py"]).script_args == []
    argv = ["verify", "m.py", "--", "-n.py"]  # another command keeps argparse's own meaning of --: positionals
    parsed = build_parser(argv).parse_args(argv)
    assert parsed.missions == ["m.py", "-n.py"] and not hasattr(parsed, "script_args")


def test_a_timer_skips_the_periods_a_long_callback_overran_as_rcl_does(monkeypatch):
    """rcl_timer_call: the next call a period after the one that was due; periods missed are skipped, the next
    call the first period's end not before now (one exactly now is due at once)."""
    from aeroexec.dialects.aerostack2.rclpy import timer as timers
    from aeroexec.dialects.aerostack2.rclpy.clock import ROSClock

    monkeypatch.setattr(timers, "now_ns", lambda: 0)
    calls = []
    timer = timers.Timer(lambda: calls.append(1), 1_000_000_000, ROSClock())
    assert timer.due() == 1_000_000_000
    timer.call(1_000_000_000)
    assert timer.due() == 2_000_000_000 and calls == [1]
    timer.call(5_500_000_000)  # called late (a take-off waited for in the callback before)
    assert timer.due() == 6_000_000_000
    timer.call(7_000_000_000)
    assert timer.due() == 7_000_000_000
    timer.cancel()
    assert timer.is_canceled() and timer.due() is None
