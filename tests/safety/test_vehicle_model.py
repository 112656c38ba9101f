"""One vehicle model for every estimate: verify's route, the safety rules' return estimates and checks before
flight cost a flight the same way (``aeroexec.drones.vehicle``), and what they predict is what the simulated
drone, whose battery the model follows, does."""

from __future__ import annotations

import aeroexec.engine.api as api
import pytest
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.config import SimConfig
from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.catalog import default_catalog
from aeroexec.engine.engine import Engine
from aeroexec.engine.safety import static
from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.route import estimate_route

POINTS = [(16, 0, 8), (16, 16, 12), (-16, 16, 12)]
TREE = ('<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><TAKE_OFF ALTITUDE="8"/>'
        + "".join(f'<GO_TO_POINT COORDINATES="{x}, {y}, {z}"/>' for x, y, z in POINTS)
        + '<LAND/></Sequence></BehaviorTree></root>')
CONFIG = SimConfig(battery_hover_minutes=6)


def test_verify_s_route_and_the_safety_rules_route_cost_the_same_flight_the_same():
    document = read_xml(TREE, "route.xml")
    route = estimate_route(document, None, CONFIG)
    model = VehicleModel(CONFIG)
    waypoints = static.route(document, "route.xml", model)
    assert [w.point for w in waypoints] == [(0.0, 0.0, 8.0), *[tuple(map(float, p)) for p in POINTS]]
    seconds, landing = model.land(12.0)
    assert route.battery == pytest.approx(waypoints[-1].charge - landing, abs=0.01)
    assert route.duration == pytest.approx(waypoints[-1].seconds + seconds, abs=0.01)


def test_the_model_predicts_what_the_simulated_drone_uses():
    estimate = estimate_route(read_xml(TREE, "route.xml"), None, CONFIG)
    drone = SimulatedDrone(config=CONFIG)
    engine = Engine(drone, catalog=default_catalog())

    def mission() -> None:
        api.execute_behavior("TAKE_OFF", ALTITUDE=8)
        for point in POINTS:
            assert api.execute_behavior("GO_TO_POINT", COORDINATES=list(point)) == "GOAL_ACHIEVED"
        api.execute_behavior("LAND")

    engine.run(mission, max_time=300)
    landed = engine.log.events("drone_landed")[0].time
    took_off = engine.log.events("activated")[0].time
    engine.stop()
    used, predicted = 100.0 - drone.telemetry().battery_percent, 100.0 - estimate.battery
    assert predicted == pytest.approx(used, rel=0.03), (predicted, used)  # 10.9 % predicted, 11.0 % used
    assert estimate.duration == pytest.approx(landed - took_off, rel=0.03)  # 36.4 s predicted, 36.8 s flown
