"""ROS 2 messages an Aerostack2 script uses as data (a path of PoseStamped, a Point, an LED colour, a GPS fix),
rclpy's logging, a publisher's messages (into the event log), and a script's own modules beside it: served as under
``python3``, with nothing of ROS 2 needed; what needs a ROS 2 graph (a subscription) is still refused by name."""

from __future__ import annotations

import re

import pytest
from flying import fly, world

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


LEDS = """import rclpy
from as2_python_api.drone_interface import DroneInterface
from std_msgs.msg import ColorRGBA


class Dancer(DroneInterface):
    def __init__(self, name):
        super().__init__(name, verbose=False)
        self.led_pub = self.create_publisher(ColorRGBA, f"/{name}/leds/control", 10)

    def colour(self, r, g, b):
        msg = ColorRGBA()
        msg.r, msg.g, msg.b = r / 255.0, g / 255.0, b / 255.0
        self.led_pub.publish(msg)


rclpy.init()
uav = Dancer("drone0")
status = uav.create_publisher(ColorRGBA, "status", 10)
uav.arm()
uav.offboard()
uav.takeoff(1.0, 0.5)
uav.colour(255, 0, 0)
status.publish(ColorRGBA(g=1.0))
uav.land(0.5)
"""


def test_an_led_publisher_flies_and_its_messages_are_in_the_event_log(tmp_path, capsys):
    """challenge_multi_drone's swarm: a DroneInterface of its own publishing LED colours (ColorRGBA) was refused
    before flight (DroneInterface.create_publisher); now it flies, and each message is in the event log, on its
    topic (a relative one in the drone's namespace, as ROS 2 resolves it), where the LEDs' plugin would get it."""
    script = tmp_path / "leds.py"
    script.write_text(LEDS)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, L]
    assert [(r["behavior"], r["detail"], r["data"]["where"]) for r in flight.kinds("published")] == [
        ("/drone0/leds/control", "std_msgs.msg.ColorRGBA(r=1.0, g=0.0, b=0.0, a=0.0)", "leds.py:14"),
        ("/drone0/status", "std_msgs.msg.ColorRGBA(r=0.0, g=1.0, b=0.0, a=0.0)", "leds.py:24")]


QOS = """import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data, qos_profile_system_default
from as2_python_api.drone_interface import DroneInterface
from std_msgs.msg import ColorRGBA

rclpy.init()
uav = DroneInterface("drone0")
assert qos_profile_sensor_data.depth == 5 and qos_profile_sensor_data.reliability == ReliabilityPolicy.BEST_EFFORT
leds = uav.create_publisher(ColorRGBA, "leds/control", qos_profile_system_default)
status = uav.create_publisher(ColorRGBA, "status", QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
uav.arm()
uav.offboard()
uav.takeoff(1.0, 0.5)
leds.publish(ColorRGBA(r=1.0))
status.publish(ColorRGBA(g=1.0))
uav.land(0.5)
"""


def test_qos_profiles_are_data_for_the_publishers_served(tmp_path, capsys):
    """rclpy.qos's profiles given to a publisher (qos_profile_system_default, a QoSProfile of the script's) were
    refused before flight as ROS 2 beyond the drone interface; they are data, with rclpy's values: the script flies
    and its messages are in the event log."""
    script = tmp_path / "qos.py"
    script.write_text(QOS)
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, L]
    assert [(r["behavior"], r["data"]["where"]) for r in flight.kinds("published")] == [
        ("/drone0/leds/control", "qos.py:14"), ("/drone0/status", "qos.py:15")]


def test_a_qos_profile_without_history_or_depth_fails_as_in_rclpy(tmp_path, capsys):
    script = tmp_path / "bad_qos.py"
    script.write_text(QOS.replace("QoSProfile(depth=10, reliability", "QoSProfile(reliability"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1
    assert [r for r in flight.kinds("activated") if r["data"]["source"] == "mission"] == []  # it failed on the ground
    assert [r["detail"] for r in flight.kinds("mission_failed")] == [
        "bad_qos.py at bad_qos.py:10: InvalidQoSProfileException: Invalid QoSProfile: History and/or depth settings "
        "are required."]


def test_publishing_what_aeroexec_does_not_serve_is_refused_by_name_before_flight(tmp_path, capsys):
    script = tmp_path / "camera.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface import DroneInterface\n"
                      "from sensor_msgs.msg import Image\n\nrclpy.init()\nuav = DroneInterface('drone0')\n"
                      "frames = uav.create_publisher(Image, 'frames', 10)\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "camera.py:7:31: error: WRONG_FORMAT: sensor_msgs.msg.Image: this mission uses ROS 2 beyond the drone " \
           "interface" in flight.err


def test_an_unused_image_stack_import_does_not_make_a_ros_2_script_a_ros_1_one(tmp_path, capsys, monkeypatch):
    """cv_bridge is ROS 2's as much as ROS 1's: importing it (and OpenCV, not installed here) without using them
    leaves a ROS 2 script's LED colour served; OpenCV's import was an error ("cannot be found"), and the colour was
    refused in ROS 1's words."""
    from aeroexec.dialects import ros

    monkeypatch.setattr(ros, "installed", lambda module: False)  # as on this machine: no OpenCV
    script = tmp_path / "lights.py"
    script.write_text(LEDS.replace("import rclpy\n", "import rclpy\nfrom cv_bridge import CvBridge\nimport cv2\n"))
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 0, flight.err
    assert "lights.py:2:1: warning: cv_bridge.CvBridge is imported but never used: the mission runs without it " \
           "(a use would be refused: this mission uses ROS 2 beyond the drone interface)" in flight.err
    assert "lights.py:3:1: warning: cv2 is imported but never used: the mission runs without it (a use would be " \
           "refused: OpenCV (cv2) is not installed here, and aeroexec's drone interface gives no camera images to " \
           "process)" in flight.err
    assert len(flight.kinds("published")) == 2


def test_a_use_of_opencv_where_it_is_not_installed_is_refused_naming_it(tmp_path, capsys, monkeypatch):
    from aeroexec.dialects import ros

    monkeypatch.setattr(ros, "installed", lambda module: False)
    script = tmp_path / "show.py"
    script.write_text("import rclpy\nimport cv2\nfrom as2_python_api.drone_interface import DroneInterface\n\n"
                      "rclpy.init()\nuav = DroneInterface('drone0')\ncv2.waitKey(1)\n")
    flight = fly(script, tmp_path, capsys)
    assert flight.status == 1 and not flight.records
    assert "show.py:7:1: error: WRONG_FORMAT: cv2.waitKey: OpenCV (cv2) is not installed here, and aeroexec's " \
           "drone interface gives no camera images to process" in flight.err


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


GEO_PATH = """import rclpy
from as2_python_api.drone_interface_gps import DroneInterfaceGPS
from geographic_msgs.msg import GeoPath, GeoPoseStamped

rclpy.init()
uav = DroneInterfaceGPS("drone0")
path = GeoPath()
for lat, lon in ((40.00005, -3.0), (40.00005, -3.00005)):
    pose = GeoPoseStamped()
    pose.pose.position.latitude = lat
    pose.pose.position.longitude = lon
    pose.pose.position.altitude = 3.0
    path.poses.append(pose)
uav.arm()
uav.offboard()
uav.takeoff(3.0, 1.0)
uav.follow_path(path, 2.0)
uav.land(0.5)
"""


def test_a_geo_path_of_geo_poses_flies_from_the_gps_origin(tmp_path, capsys):
    """geographic_msgs' GeoPath of GeoPoseStamped, as a GPS drone interface's follow_path takes it: it was refused
    as ROS 2 beyond the drone interface."""
    script = tmp_path / "geo_path.py"
    script.write_text(GEO_PATH)
    flight = fly(script, tmp_path, capsys, world_file=world(tmp_path, 40.0, -3.0))
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, F, L]
    path = [r["detail"] for r in flight.kinds("activated") if r["behavior"] == F][0]
    numbers = [float(n) for n in re.findall(r"-?[\d.]+(?:e-?\d+)?", path.split("SPEED")[0])]
    assert numbers == pytest.approx([0.0, 5.55, 3.0, -4.26, 5.55, 3.0], abs=0.05)  # 0.00005 deg: 5.55 m N, 4.26 m W
