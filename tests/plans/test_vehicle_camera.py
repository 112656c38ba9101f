"""Camera items on a MAVSDK vehicle (``aeroexec sim`` as PX4 and as ArduPilot, at the plan's home): with a camera
(``aeroexec sim --camera``: a MAVLink camera component) the vehicle's camera takes the photos
(MAV_CMD_IMAGE_START_CAPTURE); without one the run warns before flight and each photo behavior says in the log that
it skips them; QGroundControl's sample plan flies to completion either way.

The vehicle is ``aeroexec sim`` in a process of its own, as an operator runs it beside ``aeroexec run``: in the
test's process, its thread shared the interpreter with the engine and the MAVSDK adapter, and on a loaded machine
it went unscheduled while they ran, the adapter's own loop on time (with eight busy processes beside it, load 15:
silences of 1.05 to 1.49 s in 4 flights, the link limit 1.5 s; in its own process 0.52 to 1.01 s in 6).

The vehicle's battery lasts 40 minutes of hover (``--vehicle``, given to the run too): the engine follows a
vehicle 20 times faster than real time on the wall clock, so each wall second it takes to answer an arrival is
20 s of hover, and on the default 20 minutes the survey (11% at landing by verify's estimate) ran below 10% and
the low-battery LAND took it over on a loaded machine (the run suspended). The photos are what is tested here."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.flight.session import FlightSession
from aeroexec.flight.spec import FlightSpec
from free_ports import free_udp_port
from patience import hang_guard
from real_missions import DATA

pytestmark = pytest.mark.mavsdk

SPEED = 20.0  # simulated seconds per wall second
ENDURANCE = 40  # minutes of hover on a full battery: the survey lands with about half of it
SAMPLE = DATA / "mavsdk" / "qgroundcontrol_sample.plan"  # QGroundControl's own sample: photos, a survey's trigger
SURVEY = Path(__file__).parents[2] / "missions" / "field_survey.plan"  # 6.8 km, a camera triggered by distance


def fly_sample(tmp_path, autopilot: str, camera: bool, plan: Path = SAMPLE):
    """Fly ``plan`` with ``aeroexec run``'s flight session against ``aeroexec sim`` at the plan's home: the
    outcome, the event log, the problems reported before flight, and the photos the vehicle saved (in order)."""
    home = json.loads(plan.read_text())["mission"]["plannedHomePosition"]
    port = free_udp_port()
    photos = tmp_path / "vehicle_camera"
    vehicle_profile = tmp_path / "vehicle.yaml"
    vehicle_profile.write_text(f"endurance: {ENDURANCE}\n")
    command = [sys.executable, "-m", "aeroexec.cli.main", "sim", "--home", ",".join(str(v) for v in home),
               "--connect", f"udpout://127.0.0.1:{port}", "--speed", str(SPEED), "--autopilot", autopilot,
               "--vehicle", str(vehicle_profile), *(["--camera", str(photos)] if camera else [])]
    problems: list = []
    with (tmp_path / "sim.log").open("w") as log:
        vehicle = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT)
        try:
            spec = FlightSpec(mission=plan, drone=f"mavsdk:udpin://127.0.0.1:{port}", output=str(tmp_path / "run"),
                              register=False, ready_timeout=hang_guard(60.0), vehicle=str(vehicle_profile))
            session = FlightSession(spec, notify=lambda text: None, report=problems.append)
            outcome = session.fly()
        finally:
            vehicle.terminate()  # as Ctrl-C: it stops its vehicle and says so
            try:
                status = vehicle.wait(hang_guard(20.0))
            except subprocess.TimeoutExpired:
                vehicle.kill()
                status = vehicle.wait()
    said = (tmp_path / "sim.log").read_text()
    assert status == 0 and "simulated drone stopped" in said, said
    saved = sorted(photos.glob("image_*.png"), key=lambda p: int(p.stem.split("_")[1])) if camera else []
    return outcome, session.engine.log.events(), problems, saved


@pytest.mark.parametrize("autopilot", ["px4", "ardupilot"])
def test_with_a_camera_the_vehicle_takes_the_sample_plan_s_photos(tmp_path, autopilot):
    outcome, events, problems, saved = fly_sample(tmp_path, autopilot, camera=True)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    taken = [e for e in events if e.kind == "photo_taken"]
    assert taken and all(e.data.get("camera") == "vehicle" for e in taken)
    assert [p.name for p in saved] == [f"image_{n}.png" for n in range(1, len(taken) + 1)]  # each one the vehicle's
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
    outcome, events, problems, saved = fly_sample(tmp_path, autopilot, camera=True, plan=SURVEY)
    assert outcome.exit_status == 0, (outcome.status, outcome.faults)
    taken = [e for e in events if e.kind == "photo_taken" and e.behavior == "TRIGGER_CAMERA"]
    assert len(taken) >= 20 and all(e.data.get("camera") == "vehicle" for e in taken)
    # every photo the vehicle saved is in the log: taken, or asked and unanswered when the trigger stopped (its
    # reply on the way: the vehicle takes it, the log says it may have)
    unanswered = sum(e.data.get("count", 0) for e in events if e.kind == "photo_unanswered")
    said = len([e for e in events if e.kind == "photo_taken"])
    assert said <= len(saved) <= said + unanswered
