"""ROS 2 messages an Aerostack2 script uses as data (a path of PoseStamped, a Point, an LED colour, a GPS fix),
rclpy's logging, and a script's own modules beside it: served as under ``python3``, with nothing of ROS 2 needed;
what needs a ROS 2 graph (publishing) is still refused by name."""

from __future__ import annotations

import re

import pytest
from flying import fly

T, G, F, L = "TAKE_OFF", "GO_TO_POINT", "FOLLOW_PATH", "LAND"

CURVE = '''import rclpy
from math import cos, sin, pi
from as2_python_api.drone_interface import DroneInterface
from as2_msgs.msg import PoseWithID
from geometry_msgs.msg import Point, Pose, PoseStamped
from nav_msgs.msg import Path
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import ColorRGBA, Header

logger = rclpy.logging.get_logger("curve")


def curve(radius, count, height):
    path = Path()
    path.header.frame_id = "earth"
    for i in range(count):
        pose = PoseStamped(header=Header(frame_id="earth"))
        angle = 2 * pi * (i + 1) / count
        pose.pose.position.x = radius * cos(angle)
        pose.pose.position.y = radius * sin(angle)
        pose.pose.position.z = height
        path.poses.append(pose)
    return path


rclpy.init()
uav = DroneInterface("drone0", verbose=False, use_sim_time=True)
colour = ColorRGBA(r=1.0, g=0.5)
fix = NavSatFix()
fix.latitude = 40.0
uav.arm()
uav.offboard()
uav.takeoff(height=3.0, speed=1.0)
uav.go_to.go_to_point(Point(x=2.0, y=0.0, z=3.0), speed=1.0)
uav.follow_path(curve(2.0, 4, 3.0), speed=2.0)
target = PoseWithID(id="back", pose=Pose(position=Point(x=0.0, y=0.0, z=3.0)))
uav.follow_path([target], speed=1.0)
logger.info(f"curve flown, colour {colour.r}, {colour.g}, fix at {fix.latitude}")
uav.land(speed=0.5)
uav.shutdown()
rclpy.shutdown()
'''


def test_a_path_of_pose_stamped_messages_flies(tmp_path, capsys):
    script = tmp_path / "curve.py"
    script.write_text(CURVE)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, F, F, L]
    paths = [r["detail"] for r in flight.kinds("activated") if r["behavior"] == F]
    numbers = [float(n) for n in re.findall(r"-?[\d.]+(?:e-?\d+)?", paths[0].split("SPEED")[0])]
    assert numbers == pytest.approx([0, 2, 3, -2, 0, 3, 0, -2, 3, 2, 0, 3], abs=1e-9)  # the poses' positions
    assert "PATH=((0.0, 0.0, 3.0),)" in paths[1]  # a PoseWithID's pose
    goal = [r["detail"] for r in flight.kinds("activated") if r["behavior"] == G][0]
    assert "COORDINATES=(2.0, 0.0, 3.0)" in goal


def test_publishing_a_message_is_still_refused_by_name(tmp_path, capsys):
    script = tmp_path / "leds.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n"
                      "from std_msgs.msg import ColorRGBA\n\nrclpy.init()\nuav = DroneInterface('drone0')\n"
                      "leds = uav.create_publisher(ColorRGBA, '/drone0/leds/control', 10)\n"
                      "leds.publish(ColorRGBA(r=1.0))\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "leds.py:7:" in flight.err and "DroneInterface.create_publisher: this mission uses ROS 2 beyond the " \
                                          "drone interface" in flight.err


def test_a_scripts_own_module_beside_it_imports_as_under_python3(tmp_path, capsys):
    (tmp_path / "square_lib.py").write_text(
        "import rclpy\nfrom time import sleep\n\n\ndef square(uav, side):\n"
        "    for x, y in ((side, 0), (side, side), (0, side), (0, 0)):\n"
        "        uav.go_to(x, y, 2.0, 1.0)\n        sleep(0.5)\n    return rclpy.ok()\n")
    script = tmp_path / "main_square.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n"
                      "from square_lib import square\n\nrclpy.init()\nuav = DroneInterface('drone0')\n"
                      "uav.arm()\nuav.offboard()\nuav.takeoff(2.0, 1.0)\nassert square(uav, 3.0)\nuav.land(0.5)\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, G, G, G, L]  # the module's rclpy, time and drone are the script's


def test_a_module_beside_the_script_using_a_ros_2_graph_is_refused_by_name_before_flight(tmp_path, capsys):
    """rss24_demo's mission_follower.py: its module's subscription to the leader's pose was refused in flight, at
    t=0 of a run that ended failed; now before flight, at the module's own file and line."""
    (tmp_path / "follow_lib.py").write_text(  # as rss24_demo's mission/follow_drone_module.py builds its topic
        "import as2_core.as2_names as as2\n\n\ndef leader_topic(name):\n"
        "    return '/' + name + '/' + as2.topics.self_localization.pose\n")
    script = tmp_path / "follower.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n"
                      "from follow_lib import leader_topic\n\nrclpy.init()\nuav = DroneInterface('drone0')\n"
                      "print(leader_topic('drone1'))\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records  # no flight
    assert f"{tmp_path / 'follow_lib.py'}:5:" in flight.err
    assert "as2_core.as2_names.topics.self_localization.pose: this mission uses ROS 2 beyond the drone interface" \
        in flight.err
