"""QGC WPL 110 waypoint files and QGroundControl's legacy .mission read into the same items as a .plan, with
ArduPilot's readings of them; every problem at its line; a plan written back as .waypoints or .plan and read again
is the same tree, and flies the same."""

from __future__ import annotations

import math

import pytest
from aeroexec.drones.geodesy import geo_to_enu, parse_geo
from aeroexec.trees.items import items_document
from aeroexec.trees.items.readers import load_item_mission, read_item_mission
from aeroexec.trees.items.writer import WriteError, write_plan, write_waypoints
from aeroexec.trees.mission_file import read_mission_tree
from aeroexec.trees.mission_world import world_for
from aeroexec.trees.model import TreeFormatError
from real_missions import DATA, FILES, REFUSED, fly, name

HOME = "0\t1\t0\t16\t0\t0\t0\t0\t-35.363262\t149.165237\t584.000000\t1"


def wpl(*lines: str, home: str = HOME) -> str:
    return "\n".join(["QGC WPL 110", home, *lines]) + "\n"


def line(seq: int, command: int, *params: float, frame: int = 3) -> str:
    values = [*params, *([0.0] * (7 - len(params)))]
    return "\t".join([str(seq), "0", str(frame), str(command), *(f"{v:.8f}" for v in values), "1"])


def leaves(text: str, file: str = "m.waypoints") -> list[tuple[str, str, dict]]:
    return [(n.type, n.name, n.ports) for n in read_mission_tree(text, file).root.children]


def test_qgroundcontrols_own_waypoint_file_crlf_and_all_reads_home_and_items_with_their_lines():
    mission = load_item_mission(DATA / "qgroundcontrol" / "MissionPlanner.waypoints")
    assert mission.home == (47.660459, -122.103167, 5.21) and mission.home_line == 2
    assert [(i.seq, i.command, i.line) for i in mission.items] == [(n, 16, n + 2) for n in range(1, 6)]
    assert mission.items[0].params[4:] == (47.661298, -122.103274, 100.0)


@pytest.mark.parametrize("text, line, message", [
    ("QGC WPL 120\n0\t1\t0\t16\t0\t0\t0\t0\t1\t2\t3\t1\n", 1, "aeroexec reads \"QGC WPL 110\""),
    ("not a waypoint file\n", 1, "the first line must be \"QGC WPL 110\""),
    (wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 10), "1\t0\t3\t16\t0\t0\t0"), 4, "not 7 fields"),
    (wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 10), line(2, 16).replace("0.00000000", "nan", 1)), 4,
     "a field that is no finite number"),
    (wpl(home="0\t1\t0\t16\t0\t0\t0\t0\t95.0\t149.0\t584\t1"), 2, "latitude 95 is not between -90 and 90"),
])
def test_a_line_that_is_no_item_is_an_error_at_that_line(text, line, message):
    try:
        problems = read_item_mission(text, "bad.waypoints").problems
    except TreeFormatError as error:
        problems = [type("P", (), {"line": at, "message": m}) for _, at, m in error.problems]
    assert any(p.line == line and message in p.message for p in problems), [(p.line, p.message) for p in problems]


def test_ardupilots_readings_zero_is_here_and_altitude_zero_keeps_the_altitude():
    nodes = leaves(wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 20), line(2, 16, 0, 0, 0, 0, -35.3631, 149.1653, 0),
                       line(3, 19, 5, 0, 0, 0, 0, 0, 30), line(4, 21)))
    assert [n[0] for n in nodes] == ["TAKE_OFF", "GO_TO_POINT", "GO_TO_POINT", "WAIT", "LAND"]
    assert parse_geo(nodes[1][2]["COORDINATES"])[2] == 20  # altitude 0: the altitude it flies at
    here = parse_geo(nodes[2][2]["COORDINATES"])  # latitude and longitude 0: where it is, climbing to 30 m
    assert here[:2] == pytest.approx((-35.3631, 149.1653), abs=1e-7) and here[2] == 30


def test_conditions_distance_yaw_and_change_of_altitude():
    far = (-35.363262 + 0.0009, 149.165237)  # 100 m north
    nodes = leaves(wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 10), line(2, 114, 30), line(3, 203, 0, 0, 0, 0, 1),
                       line(4, 16, 0, 0, 0, 0, *far, 10), line(5, 115, 90, 20, 1, 1), line(6, 115, 270, 0, 0, 0),
                       line(7, 113, 0, 0, 0, 0, 0, 0, 25), line(8, 20)))
    kinds = [n[0] for n in nodes]
    assert kinds == ["TAKE_OFF", "GO_TO_POINT", "TAKE_PHOTO", "GO_TO_POINT", "ROTATE", "ROTATE", "GO_TO_POINT",
                     "GO_TO_POINT", "LAND"]
    home = (-35.363262, 149.165237, 584.0)
    before = geo_to_enu(parse_geo(nodes[1][2]["COORDINATES"]), home)
    waypoint = geo_to_enu(parse_geo(nodes[3][2]["COORDINATES"]), home)
    assert before[1] == pytest.approx(waypoint[1] - 30, abs=0.01)  # the photo 30 m before the waypoint
    assert nodes[4][2] == {"RELATIVE_ANGLE": "-90"} and nodes[5][2] == {"ANGLE": "180"}  # 90 clockwise; west
    assert parse_geo(nodes[6][2]["COORDINATES"])[2] == 25


def test_loiter_turns_circle_for_the_time_the_turns_take_and_the_gripper_releases_its_payload():
    nodes = leaves(wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 10), line(2, 18, 2, 0, 10), line(3, 211, 0, 0),
                       line(4, 21)))
    loiter = nodes[1]
    assert loiter[0] == "Parallel"
    circle, wait = read_mission_tree(wpl(line(1, 22, 0, 0, 0, 0, 0, 0, 10), line(2, 18, 2, 0, 10)),
                                     "m.waypoints").root.children[1].children
    assert circle.ports == {"SHAPE": "CIRCLE", "RADIUS": "10", "CLOCKWISE": "true"}
    assert float(wait.ports["DURATION"]) == pytest.approx(2 * 2 * math.pi * 10 / 2.0, abs=0.01)  # at 2 m/s
    assert nodes[2][0] == "DROP_ITEM"
    gripper = load_item_mission(DATA / "ardupilot" / "copter-gripper-mission.txt")
    assert world_for(gripper).payload == ("gripper_load",)


def test_a_mission_file_is_json_or_waypoints_by_its_first_line():
    legacy = load_item_mission(DATA / "qgroundcontrol" / "OldFileFormat.mission")
    assert legacy.home[:2] == (47.660137763851573, -122.29411931627152)
    assert [i.command for i in legacy.items] == [22, 18, 18, 16, 16, 21]
    px4 = load_item_mission(DATA / "px4" / "VTOL_TAKEOFF.mission")  # PX4's test writes WPL in a .mission
    assert px4.home is None and [i.command for i in px4.items] == [84, 16, 16, 85]


def test_items_numbered_out_of_order_are_numbered_as_uploaded_with_a_warning():
    mission = load_item_mission(DATA / "ardupilot" / "weathervane_mission.txt")  # indexes 1, 2, 4, 12
    assert [i.seq for i in mission.items] == [1, 2, 3, 4]
    assert [p.line for p in mission.problems if p.severity == "warning"] == [5, 6]


ROUND_TRIP = [p for p in FILES if name(p) not in REFUSED and "digicam" not in p.name]


def _place(value: str, home) -> tuple[float, ...] | None:
    """A port's point in ENU meters (geographic or local), None when it is no point."""
    if value.startswith("geo:"):
        return geo_to_enu(parse_geo(value), home)
    parts = value.split(",")
    return tuple(float(p) for p in parts) if len(parts) == 3 else None


def _same_ports(a, b, home) -> None:
    assert a.ports.keys() == b.ports.keys(), (a.name, a.ports, b.ports)
    for key, value in a.ports.items():
        place = _place(value, home)
        if place is not None:
            assert math.dist(place, _place(b.ports[key], home)) < 0.02, (a.name, key, value, b.ports[key])
        else:
            try:
                assert float(value) == pytest.approx(float(b.ports[key]), abs=0.01), (a.name, key)
            except ValueError:
                assert value == b.ports[key], (a.name, key)


@pytest.mark.parametrize("path", ROUND_TRIP, ids=name)
def test_a_mission_written_as_waypoints_and_as_a_plan_reads_back_as_the_same_behaviors(path):
    original = items_document(load_item_mission(path))
    mine = [n for n in original.root.walk() if n.type != "Sequence"]
    for text, suffix in ((write_waypoints(original, original.home), ".waypoints"),
                         (write_plan(original, original.home), ".plan")):
        again = items_document(read_item_mission(text, f"again{suffix}"))
        assert not [p for p in again.problems if p.severity == "error"], suffix
        theirs = [n for n in again.root.walk() if n.type != "Sequence"]
        assert [n.type for n in mine] == [n.type for n in theirs], suffix
        for a, b in zip(mine, theirs, strict=True):
            _same_ports(a, b, original.home)


def test_a_plan_converted_to_waypoints_and_back_flies_the_same_route(tmp_path):
    path = DATA / "mavsdk" / "qgroundcontrol_sample_with_survey.plan"  # a survey with its camera triggers
    original = items_document(load_item_mission(path))
    written = tmp_path / "survey.waypoints"
    written.write_text(write_waypoints(original, original.home))
    back = tmp_path / "survey_again.plan"
    back.write_text(write_plan(items_document(load_item_mission(written)), original.home))
    flights = []
    for flown in (path, back):
        status, events, _, _ = fly(flown, tmp_path / flown.stem)
        assert status.name == "SUCCESS"
        flights.append([e.data["arguments"]["COORDINATES"] for e in events if e.kind == "activated"
                        and e.behavior == "GO_TO_POINT"])
    assert len(flights[0]) == len(flights[1]) >= 8
    assert all(math.dist(a, b) < 0.05 for a, b in zip(*flights, strict=True))


def test_a_tree_that_is_no_sequence_of_items_does_not_write_as_a_plan():
    from aeroexec.trees.loaders.xml_loader import read_xml

    document = read_xml('<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><TAKE_OFF ALTITUDE="3"/>'
                        '<Fallback><CheckBelief belief="battery_level(self, high)"/><LAND/></Fallback>'
                        '</Sequence></BehaviorTree></root>', "m.xml")
    with pytest.raises(WriteError) as caught:
        write_plan(document, (47.0, 8.0, 400.0))
    (file, line, message), = caught.value.problems
    assert file == "m.xml" and message == "Fallback has no mission item: only a sequence of mission items converts " \
                                          "to a plan"
