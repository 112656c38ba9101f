"""Missions at real scale: the world generated around a mission planned on a map and moved by --home, geographic
points in any mission, argument ranges from the vehicle's limits and the world, timeouts that grow with the flight,
the route before flight (geofence, battery), and positions from the vehicle's own estimate."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.cli.sim import sim_world
from aeroexec.drones import Telemetry
from aeroexec.drones.geodesy import enu_to_geodetic, format_geo, geo_to_enu
from aeroexec.drones.sim import SimulatedDrone, default_world
from aeroexec.engine.catalog import BehaviorSpecialist, default_catalog, parse_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.errors import CatalogError, SpecificationError
from aeroexec.trees.items.readers import load_item_mission
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.mission_world import mission_world, world_for
from aeroexec.trees.route import estimate_route
from aeroexec.trees.runtime.runner import TreeMission
from real_missions import DATA

ROOT = Path(__file__).parents[2]
HOME = default_world().home


def aeroexec(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *args], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)


def xml(body: str) -> str:
    return f'<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>{body}</Sequence></BehaviorTree></root>'


def test_the_world_of_a_plan_is_an_open_field_around_it_at_its_home_with_its_fence():
    path = ROOT / "missions" / "field_survey.plan"
    world = mission_world(path)
    plan = json.loads(path.read_text())
    assert world.home == tuple(plan["mission"]["plannedHomePosition"])
    assert world.name.startswith("open field at 47.39774") and not world.obstacles
    (lo, hi) = world.bounds.lower, world.bounds.upper
    assert lo[0] < -60 and hi[0] > 1140 and lo[1] < -350 and hi[1] > 350  # the fence and a margin
    assert hi[2] >= 130 and lo[2] == 0  # the survey's 120 m and headroom
    assert [f.kind for f in world.fences] == ["inclusion polygon"]
    assert not world.inside((1200.0, 0.0, 50.0)) and world.inside((500.0, 0.0, 50.0))


def test_home_moves_the_take_off_point_and_the_items_keep_their_latitudes_and_longitudes():
    path = DATA / "px4" / "MC_mission_box.plan"
    east = enu_to_geodetic((30.0, 0.0, 0.0), HOME)  # 30 m east of the plan's home
    world = mission_world(path, home=(east[0], east[1], None))
    assert world.home == pytest.approx((east[0], east[1], 488.0))
    first = load_item_mission(path).items[1]
    x, y, _ = geo_to_enu((first.latitude, first.longitude, 0.0), world.home)
    assert x == pytest.approx(-30.0 + geo_to_enu((first.latitude, first.longitude, 0.0), HOME)[0], abs=0.01)
    assert world.bounds.lower[0] < x - 20  # still inside the field
    result = aeroexec("verify", str(path), "--home", f"{east[0]},{east[1]}")
    assert result.returncode == 0 and "30 m from the home it flies from" in result.stdout
    bad = aeroexec("verify", str(path), "--home", "91,8")
    assert bad.returncode == 2 and "'91,8' is no place on Earth: latitude 91 is not between -90 and 90" in bad.stderr


def test_a_mission_in_local_meters_keeps_the_default_field_and_sim_home_opens_a_field_there():
    assert mission_world(ROOT / "missions" / "iarc7.xml").name == default_world().name
    moved = mission_world(ROOT / "missions" / "iarc7.xml", home=(10.0, 20.0, None))
    assert moved.home == (10.0, 20.0, 0.0) and moved.obstacles == default_world().obstacles
    field = sim_world(None, (-35.36, 149.16, 584.0))
    assert field.home == (-35.36, 149.16, 584.0) and field.bounds.upper == (5000.0, 5000.0, 500.0)
    assert world_for(load_item_mission(DATA / "qgroundcontrol" / "ce_geofence_home_base.plan")).home[2] == 30


def test_geographic_points_in_a_tree_verify_against_the_world_and_fly_there(tmp_path):
    target = enu_to_geodetic((6.0, -8.0, 0.0), HOME)
    far = enu_to_geodetic((60.0, 0.0, 0.0), HOME)
    text = xml(f'<TAKE_OFF ALTITUDE="4"/><GO_TO_POINT COORDINATES="{format_geo(target[0], target[1], 5)}"/>'
               f'<GO_TO_POINT COORDINATES="{format_geo(far[0], far[1], 5)}"/><LAND/>')
    document = read_xml(text, "geo.xml")
    from aeroexec.trees.verify import verify_document

    problems = verify_document(document, default_catalog(), world=default_world())
    (error,) = [p for p in problems if p.severity == "error"]
    assert "(60, 0, 5) is outside the world's bounds (x -20..20" in error.message  # placed from the world's home
    document.root.children.pop(2)
    engine = Engine(SimulatedDrone(default_world()), obstacles=default_world(), output_dir=tmp_path)
    try:
        assert TreeMission(document, engine).run(120.0).name == "SUCCESS"
        assert math.dist(engine.drone.telemetry().position[:2], (6.0, -8.0)) < 0.5
        flown = [e for e in engine.log.events("activated") if e.behavior == "GO_TO_POINT"]
        assert flown[0].data["arguments"]["COORDINATES"] == pytest.approx((6.0, -8.0, 5.0), abs=0.01)
    finally:
        engine.stop()
    with pytest.raises(SpecificationError) as caught:
        BehaviorSpecialist().check_request("GO_TO_POINT", {"COORDINATES": "geo:95,8,5"})
    assert "geo:LAT,LON,ALT in the world" in caught.value.message


def test_ranges_come_from_the_vehicles_limits_and_a_paper_catalog_still_reads_as_it_was():
    catalog = default_catalog()
    assert catalog.vehicle_limits == {"max_altitude": 500, "max_distance": 5000, "max_speed": 12,
                                      "max_flight_time": 1200}
    altitude = catalog.behaviors["TAKE_OFF"].arguments["ALTITUDE"]
    assert (altitude.minimum, altitude.maximum) == (0.5, 500)
    specialist = BehaviorSpecialist(catalog)
    specialist.check_request("GO_TO_POINT", {"COORDINATES": (3000.0, -2000.0, 120.0)})  # 3.6 km away: in reach
    with pytest.raises(SpecificationError) as caught:
        specialist.check_request("GO_TO_POINT", {"COORDINATES": (4000.0, 4000.0, 10.0)})
    assert "x and y within 5000 m of home, z within 500 m" in caught.value.message
    paper = parse_catalog((ROOT / "tests" / "engine" / "data" / "appendix_b.yaml").read_text(), "b.yaml")
    coordinates = paper.behaviors["GO_TO_POINT"].arguments["COORDINATES"]
    assert (coordinates.minimum, coordinates.maximum, coordinates.in_world) == (-100, 100, False)
    with pytest.raises(CatalogError) as bad:
        parse_catalog("vehicle_limits: {max_altitude: 100}\nbehavior_descriptors:\n- behavior: TAKE_OFF\n"
                      "  arguments:\n  - {argument: ALTITUDE, allowed_values: [0, max_hight]}\n", "c.yaml")
    assert "c.yaml:5" in str(bad.value) and "a number or a vehicle limit (max_altitude)" in str(bad.value)


def test_timeouts_grow_with_the_altitude_and_the_distance_asked(tmp_path):
    world = sim_world(None, HOME)
    text = xml('<TAKE_OFF ALTITUDE="50"/><GO_TO_POINT COORDINATES="800, 0, 50" SPEED="10"/><LAND/>')
    engine = Engine(SimulatedDrone(world), obstacles=world, output_dir=tmp_path)
    try:
        assert TreeMission(read_xml(text, "far.xml"), engine).run(900.0).name == "SUCCESS"  # 30 s once timed out
        timeouts = {e.behavior: e.data["timeout"] for e in engine.log.events("activated")
                    if e.behavior in ("TAKE_OFF", "GO_TO_POINT", "LAND")}
    finally:
        engine.stop()
    assert timeouts["TAKE_OFF"] == pytest.approx(30 + 1.5 * 50 / 1.5, abs=0.1)
    assert timeouts["GO_TO_POINT"] == pytest.approx(120 + 1.5 * (800 / 10 + 3), abs=0.5)
    assert timeouts["LAND"] > 90 + 1.5 * 50 / 0.7 - 1


def test_the_route_is_refused_where_the_battery_runs_out_and_where_it_crosses_the_fence():
    ring = [enu_to_geodetic((x, y, 0.0), HOME)[:2] for x, y in ((-100, -100), (100, -100), (100, 100), (-100, 100))]
    legs = "".join(f'<GO_TO_POINT name="item {n} WAYPOINT" COORDINATES="{format_geo(lat, lon, 20)}" SPEED="12"/>'
                   for n, (lat, lon) in enumerate(ring * 6, start=2))
    document = read_xml(xml(f'<TAKE_OFF ALTITUDE="20"/>{legs}<LAND/>'), "loops.xml")
    world = sim_world(None, HOME)
    estimate = estimate_route(document, world)
    assert estimate.length == pytest.approx(20 + 141.4 + 23 * 200 + 20, abs=5)
    assert not [p for p in estimate.problems if p.severity == "error"]
    many = read_xml(xml(f'<TAKE_OFF ALTITUDE="20"/>{legs * 4}<LAND/>'), "many.xml")
    estimate = estimate_route(many, world)
    (error,) = [p for p in estimate.problems if p.severity == "error"]
    assert re.search(r"item \d+: the battery runs down to its 7% failsafe here: the route \(19\.\d km, \d+ min\) "
                     r"needs \d+% of a full battery, \d+% more than the drone has", error.message)
    from aeroexec.drones.sim.geofence import Fence

    fenced = default_world().__class__(home=HOME, bounds=world.bounds, fences=(Fence(False, center=(0.0, 0.0),
                                                                                    radius=30.0, line=7),))
    crossing = read_xml(xml('<TAKE_OFF ALTITUDE="20"/><GO_TO_POINT COORDINATES="-60, -60, 20"/>'
                            '<GO_TO_POINT COORDINATES="60, 60, 20"/><LAND/>'), "cross.xml")
    fenced_home = read_xml(xml('<TAKE_OFF ALTITUDE="20"/>'), "x.xml")
    assert estimate_route(fenced_home, fenced) is not None
    problems = estimate_route(crossing, fenced).problems
    assert any("goes inside the exclusion circle of line 7 on its way (geofence)" in p.message for p in problems)


def test_positions_come_from_the_vehicles_own_estimate_with_its_accuracy(tmp_path):
    class Autopilot(SimulatedDrone):
        estimates_position = True  # a real vehicle's telemetry is its own estimate

        def telemetry(self) -> Telemetry:
            from dataclasses import replace

            return replace(super().telemetry(), position_accuracy=0.8)

    world = default_world()
    engine = Engine(Autopilot(world), obstacles=world, output_dir=tmp_path)
    text = xml('<SELF_LOCALIZE_BY_ODOMETRY _wait_for_completion="false"/><TAKE_OFF ALTITUDE="3"/>'
               '<GO_TO_POINT COORDINATES="15, 15, 3"/><GO_TO_POINT COORDINATES="-15, -15, 3"/>')
    try:
        assert TreeMission(read_xml(text, "odometry.xml"), engine).run(120.0).name == "SUCCESS"
        engine.step(0.2)
        believed = engine.memory.query("position(self, ?P)")["?P"]
        assert math.dist(believed, engine.drone.telemetry().position) < 0.2  # no drift after 60 m of flight
        assert engine.memory.query("position_accuracy(self, ?M)")["?M"] == 0.8
    finally:
        engine.stop()


def test_run_flies_a_plan_at_home_given_and_the_log_says_where(tmp_path):
    path = DATA / "px4" / "MC_mission_box.plan"
    east = enu_to_geodetic((30.0, 0.0, 0.0), HOME)
    result = aeroexec("run", str(path), "--plain", "--home", f"{east[0]},{east[1]},488", "--output", str(tmp_path))
    assert result.returncode == 0, result.stderr
    first = json.loads((tmp_path / "events.jsonl").read_text().splitlines()[0])
    assert first["home"] == pytest.approx([east[0], east[1], 488.0], abs=1e-7)
    assert first["bounds"][0][0] < -45 and first["bounds"][1][0] > 0  # the field around the box, 30 m west


def test_convert_refuses_what_verify_refuses_the_route_too(tmp_path):
    path = DATA / "qgroundcontrol" / "ArduPilotSITL-ArduCopter.plan"
    result = aeroexec("convert", str(path), "-o", str(tmp_path / "copter.waypoints"))
    assert result.returncode == 1 and "item 6: the battery runs down to its 7% failsafe here" in result.stderr
    assert "nothing written" in result.stderr and not (tmp_path / "copter.waypoints").exists()
    ok = aeroexec("convert", str(DATA / "px4" / "MC_mission_box.plan"), "-o", str(tmp_path / "box.waypoints"))
    assert ok.returncode == 0 and (tmp_path / "box.waypoints").read_text().startswith("QGC WPL 110\n0\t1\t0\t16\t")
    assert aeroexec("verify", str(tmp_path / "box.waypoints")).returncode == 0


def test_the_field_a_log_describes_is_the_world_the_flight_had():
    from aeroexec.drones.sim.open_field import field_of

    world = mission_world(ROOT / "missions" / "field_survey.plan")
    again = field_of(list(world.home), [list(world.bounds.lower), list(world.bounds.upper)])
    assert (again.home, again.bounds, again.name) == (world.home, world.bounds, world.name)
