"""Camera items on a MAVSDK vehicle (``aeroexec sim`` as PX4 and as ArduPilot, at the plan's home): with a camera
(``aeroexec sim --camera``: a MAVLink camera component) the vehicle's camera takes the photos
(MAV_CMD_IMAGE_START_CAPTURE); without one the run warns before flight and each photo behavior says in the log that
it skips them; QGroundControl's sample plan flies to completion either way."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from aeroexec.cli.sim import sim_world
from aeroexec.drones.sim import SimulatedDrone
from aeroexec.drones.sim.mavlink.vehicle import MavlinkVehicle
from aeroexec.flight.session import FlightSession
from aeroexec.flight.spec import FlightSpec
from free_ports import free_udp_port
from real_missions import DATA

pytestmark = pytest.mark.mavsdk

SPEED = 20.0  # simulated seconds per wall second
SAMPLE = DATA / "mavsdk" / "qgroundcontrol_sample.plan"  # QGroundControl's own sample: photos, a survey's trigger
SURVEY = Path(__file__).parents[2] / "missions" / "field_survey.plan"  # 6.8 km, a camera triggered by distance


def fly_sample(tmp_path, autopilot: str, camera: bool, plan: Path = SAMPLE):
    home = json.loads(plan.read_text())["mission"]["plannedHomePosition"]
    port = free_udp_port()
    vehicle = MavlinkVehicle(SimulatedDrone(sim_world(None, tuple(home))), connect=f"udpout://127.0.0.1:{port}",
                             speed=SPEED, autopilot=autopilot, camera=camera,
                             camera_folder=tmp_path / "vehicle_camera" if camera else None)
    vehicle.start()
    problems: list = []
    try:
        spec = FlightSpec(mission=plan, drone=f"mavsdk:udpin://127.0.0.1:{port}", output=str(tmp_path / "run"),
                          register=False, ready_timeout=60.0)
        session = FlightSession(spec, notify=lambda text: None, report=problems.append)
        outcome = session.fly()
        return outcome, session.engine.log.events(), problems, vehicle
    finally:
        vehicle.stop()


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_with_a_camera_the_vehicle_takes_the_sample_plan_s_photos(tmp_path, autopilot):
    outcome, events, problems, vehicle = fly_sample(tmp_path, autopilot, camera=True)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    taken = [e for e in events if e.kind == "photo_taken"]
    assert taken and all(e.data.get("camera") == "vehicle" for e in taken)
    assert len(vehicle.camera.images) == len(taken)  # each one the vehicle's camera took
    assert sorted(p.name for p in (tmp_path / "vehicle_camera").iterdir())[:1] == ["image_1.png"]
    assert not [e for e in events if e.kind == "photo_skipped"]
    assert not [p for p in problems if "no camera" in p.message]


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_without_a_camera_the_sample_plan_flies_with_a_warning_and_its_photos_skipped(tmp_path, autopilot):
    outcome, events, problems, _ = fly_sample(tmp_path, autopilot, camera=False)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    warned = [p for p in problems if "the vehicle has no camera" in p.message]
    assert len(warned) == 1 and warned[0].severity == "warning" and warned[0].line > 0
    assert [e for e in events if e.kind == "photo_skipped"]
    assert not [e for e in events if e.kind == "photo_taken"]


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_a_survey_s_distance_trigger_takes_its_photos_through_the_vehicle_s_camera(tmp_path, autopilot):
    outcome, events, problems, vehicle = fly_sample(tmp_path, autopilot, camera=True, plan=SURVEY)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    taken = [e for e in events if e.kind == "photo_taken" and e.behavior == "TRIGGER_CAMERA"]
    assert len(taken) >= 20 and all(e.data.get("camera") == "vehicle" for e in taken)
    assert len(vehicle.camera.images) == len([e for e in events if e.kind == "photo_taken"])
