"""Aerostack2's missions were written for Gazebo's empty world: run alone (no world file) they fly in open ground
like it, placed at the GPS origin they name, not in the paper's field (whose walls and tower stand where they fly)."""

from __future__ import annotations

import math

from aeroexec.trees.mission_world import mission_world
from flying import SCRIPTS, TREES, fly

T, G, F, L = "TAKE_OFF", "GO_TO_POINT", "FOLLOW_PATH", "LAND"


def test_aerostack2_example1_flies_without_a_world_file(tmp_path, capsys):
    flight = fly(SCRIPTS / "as2_example1.py", tmp_path, capsys, world_file=None)  # go_to(0, 5, 3): no wall here
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, G, F, L]
    started = flight.records[0]
    assert started["bounds"][0][0] <= -100 and started["bounds"][1][0] >= 100  # open ground, not the 40 m field
    assert "2.1 m from" not in flight.err


def test_aerostack2_basic_mission_tree_flies_without_a_world_file(tmp_path, capsys):
    flight = fly(TREES / "as2_basic_mission.xml", tmp_path, capsys, world_file=None)  # GoTo 5;5;2: no tower here
    assert flight.status == 0, flight.err
    assert flight.achieved() == [T, G, L]


def test_a_gps_script_flies_at_its_origin(tmp_path, capsys):
    flight = fly(SCRIPTS / "f450_mission_gps_2.py", tmp_path, capsys, world_file=None)
    assert flight.status == 0, flight.err
    assert flight.records[0]["home"] == [40.158194, -3.380795, 0.0]  # gps.set_origin(origin): the world is there
    assert flight.achieved() == [T, G, G, L]
    goal = [r for r in flight.kinds("activated") if r["behavior"] == G][0]["detail"]
    assert "COORDINATES=(-8.349, -1.221, 2.0)" in goal


def test_a_gps_script_without_an_origin_flies_at_its_first_point(tmp_path, capsys):
    flight = fly(SCRIPTS / "gazebo_mission_gps.py", tmp_path, capsys, world_file=None)
    assert flight.status == 0, flight.err
    assert flight.records[0]["home"] == [40.4405287, -3.6898277, 0.0]
    assert flight.achieved() == [T, *[G] * 12, L]


def test_a_mission_looking_for_markers_keeps_the_field_with_the_markers(tmp_path):
    script = tmp_path / "markers.py"
    script.write_text("from as2_python_api.drone_interface import DroneInterface\n"
                      "uav = DroneInterface('drone0')\nuav.load_module('detect_aruco_markers_behavior')\n")
    assert mission_world(script).name == "default field"
    assert mission_world(SCRIPTS / "as2_example1.py").name.startswith("open ground at 47.39774, 8.54559")


def test_a_gps_interfaces_follow_path_places_the_ground_at_its_first_point(tmp_path, capsys):
    """A DroneInterfaceGPS's follow_path takes GPS points: with no origin set, the first of them places the ground,
    as a go_to_gps_point's does (else they would lie 1 000 km from the default home)."""
    script = tmp_path / "gps_path.py"
    script.write_text("import rclpy\nfrom as2_python_api.drone_interface_gps import DroneInterfaceGPS\n"
                      "rclpy.init()\nuav = DroneInterfaceGPS('drone0')\nuav.offboard()\nuav.arm()\nuav.takeoff(2.0)\n"
                      "uav.follow_path([[40.441055, -3.6888145, 2.0], [40.441108, -3.6887864, 2.0]], 1.0)\n"
                      "uav.land()\nuav.shutdown()\nrclpy.shutdown()\n")
    flight = fly(script, tmp_path, capsys, world_file=None)
    assert flight.status == 0, flight.err
    assert flight.records[0]["home"] == [40.441055, -3.6888145, 0.0]
    assert flight.achieved() == [T, F, L]
    path = [r for r in flight.kinds("activated") if r["behavior"] == F][0]["arguments"]["PATH"]
    assert path[0] == [0.0, 0.0, 2.0] and math.dist(path[1][:2], (2.384, 5.887)) < 0.01
